/**
 * The Rehab Dongle and hand state machine (hannes-hand-simulator.ts) on bytes written here from
 * docs/protocols.md ("Hannes"), in every chunking: the original's whole sequence with the exact
 * replies, the decoded references, and malformed input counted with the stream recovering. The
 * machine on a pty against the HannesHand block is tests/integration/hannes-simulate.test.ts.
 */
import { describe, expect, test } from "vitest";
import { hannesDongleSimulatorOptions } from "./hannes-dongle-simulator";
import { HannesHandMachine, jointNames, scanReply, scanDevices } from "./hannes-hand-simulator";

const text = (s: string): number[] => Array.from(s, (c) => c.charCodeAt(0));
/** `%` payload `&` CR LF. */
const pkt = (...p: number[]): number[] => [0x25, ...p, 0x26, 0x0d, 0x0a];
const ACK = "%\x02&\r\n";
const NACK = "%\x03&\r\n";

function machine(names?: string[]) {
  const out: string[] = [];
  const log: string[] = [];
  const m = new HannesHandMachine({
    ...(names ? { names } : {}),
    record: true,
    write: (b) => out.push(String.fromCharCode(...b)),
    log: (l) => log.push(l),
  });
  return { m, out, log, replies: () => out.join("") };
}

/** What HannesHand sends, from the docs' tables: handshake, two references, the end. */
const SESSION: number[] = [
  ...text("$$$"),
  ...text("scan\r\n"),
  ...text("con 2\r\n"),
  ...pkt(0x00),
  ...pkt(0x0e, 0x00, 0x64),
  ...pkt(0x0e, 0x05, 0x03),
  ...pkt(0x01),
  ...pkt(0x1e, 0x00, 42, 0xce, 75, 0x00, 0x03, 0x0a, 0, 0, 0), // hand 42, P/S −50, F/E 75, thumb 10
  ...pkt(0x1e, 0x00, 100, 0x64, 0, 0x00, 0x03, 0x9c, 0, 0, 0), // hand 100, P/S 100, thumb −100
  ...pkt(0x1e, 0x00, 0, 0, 80, 0x00, 0x03, 0, 0, 0, 0), // the neutral pose
  ...pkt(0x00),
  ...text("$$$"),
  ...text("dct\r\n"),
];

describe("the original's session", () => {
  test.each([1, 2, 3, 7, 13, SESSION.length])(
    "in chunks of %i bytes: records, replies and state exact",
    (chunk) => {
      const { m, replies } = machine(["HannesL", "HannesR"]);
      for (let i = 0; i < SESSION.length; i += chunk) {
        m.receive(Uint8Array.from(SESSION.slice(i, i + chunk)));
      }
      expect(m.records).toEqual([
        { text: "$$$" },
        { text: "scan" },
        { text: "con 2" },
        { packet: [0] },
        { packet: [14, 0, 0x64] },
        { packet: [14, 5, 3] },
        { packet: [1] },
        { packet: [30, 0, 42, 0xce, 75, 0, 3, 10, 0, 0, 0] },
        { packet: [30, 0, 100, 0x64, 0, 0, 3, 0x9c, 0, 0, 0] },
        { packet: [30, 0, 0, 0, 80, 0, 3, 0, 0, 0, 0] },
        { packet: [0] },
        { text: "$$$" },
        { text: "dct" },
      ]);
      expect(replies()).toBe(
        scanReply(m.devices) +
          "con 2\r\nSuccess\r\nSTREAM_MODE\r\n" +
          ACK.repeat(8) +
          "Success\r\n",
      );
      expect(m.stateText()).toBe(
        "no hand connected: hand 0 · wrist P/S 0 · wrist F/E 80 · thumb 0 · 3 references",
      );
      expect(m.applied).toEqual([
        { hand: 42, ps: -50, fe: 75, thumb: 10 },
        { hand: 100, ps: 100, fe: 0, thumb: -100 },
        { hand: 0, ps: 0, fe: 80, thumb: 0 },
      ]);
      expect(m.reference).toEqual({ hand: 0, ps: 0, fe: 80, thumb: 0 });
      expect([m.references, m.jointMask, m.controlMode, m.handMode]).toEqual([
        3,
        0x64,
        3,
        "command",
      ]);
      expect(m.connected).toBeUndefined();
      expect(m.malformedTotal).toBe(0);
    },
  );

  test("the state line after the first reference", () => {
    const { m } = machine(["HannesL", "HannesR"]);
    const first = SESSION.indexOf(0x1e) + 14; // `%`, 11 bytes, `&` CR LF
    m.receive(Uint8Array.from(SESSION.slice(0, first)));
    expect(m.stateText()).toBe(
      "HannesR (stream mode): hand 42 · wrist P/S -50 · wrist F/E 75 · thumb 10 · 1 references",
    );
  });

  test("the scan table reads as the original read it (fields 1–4 after the index)", () => {
    const lines = scanReply(scanDevices(["HannesL", "HannesR"])).split("\n");
    expect(lines.at(-2)).toBe("Success\r");
    const rows = lines
      .map((l) => l.split(" ").filter((f) => f !== ""))
      .filter((f) => f.length >= 5 && !f.includes("RSSI"));
    expect(rows.map((f) => [Number(f[1]), f[4]!.replace("\r", "")])).toEqual([
      [1, "HannesL"],
      [2, "HannesR"],
    ]);
    expect(jointNames(0x64)).toBe("thumb, wrist F/E, wrist P/S");
  });
});

describe("refused and malformed input: counted, answered, never thrown", () => {
  function connected() {
    const t = machine();
    t.m.receive(Uint8Array.from([...text("$$$con 1\r\n")]));
    t.out.length = 0;
    return t;
  }

  test("unknown command, bad end, stray bytes: NACKed or skipped, the next packet applies", () => {
    const { m, replies } = connected();
    const good = pkt(0x1e, 0x00, 7, 0, 50, 0x00, 0x03, 0, 0, 0, 0);
    m.receive(
      Uint8Array.from([
        ...[0x25, 0x63, 1, 2], // unknown command 0x63
        ...[0x25, 0x01, 0x26, 0x0a, 0x0d], // ExitCMDMode with LF CR swapped
        ...good,
        ...[0x41, 0x42, 0x43], // stray
        ...good.map((x, i) => (i === 3 ? 9 : x)), // hand 9
      ]),
    );
    expect(m.malformed).toMatchObject({ unknownCommand: 1, badEnd: 1, strayBytes: 3 });
    expect(m.reference).toEqual({ hand: 9, ps: 0, fe: 50, thumb: 0 });
    expect(m.references).toBe(2);
    expect(replies()).toBe(NACK + NACK + ACK + ACK);
    expect(m.stateText()).toBe(
      "Hannes (stream mode): hand 9 · wrist P/S 0 · wrist F/E 50 · thumb 0 · 2 references · 2 NACKed · malformed: 1 unknown command, 1 bad end, 3 stray bytes",
    );
  });

  test("values out of range and the wrong hand mode are NACKed and not applied", () => {
    const { m, replies } = connected();
    m.receive(Uint8Array.from(pkt(0x1e, 0x00, 101, 0, 50, 0x00, 0x03, 0, 0, 0, 0)));
    m.receive(Uint8Array.from(pkt(0x1e, 0x00, 10, 0x90, 50, 0x00, 0x03, 0, 0, 0, 0))); // P/S −112
    m.receive(Uint8Array.from(pkt(0x1e, 0x01, 10, 0, 50, 0x00, 0x03, 0, 0, 0, 0))); // B2 ≠ 0
    m.receive(Uint8Array.from(pkt(0x0e, 0x00, 0x27))); // JOINT_SET in stream mode
    m.receive(Uint8Array.from(pkt(0x00))); // command mode
    m.receive(Uint8Array.from(pkt(0x0e, 0x05, 0x09))); // control mode 9
    m.receive(Uint8Array.from(pkt(0x1e, 0x00, 10, 0, 50, 0x00, 0x03, 0, 0, 0, 0))); // in command mode
    expect(m.malformed).toMatchObject({ badValue: 4, wrongMode: 2 });
    expect(replies()).toBe(NACK.repeat(4) + ACK + NACK.repeat(2));
    expect([m.references, m.jointMask, m.controlMode]).toEqual([0, undefined, undefined]);
    expect(m.reference).toEqual({ hand: 0, ps: 0, fe: 0, thumb: 0 });
  });

  test("a flood of garbage: every packet counted, the log limited, the next good one applied", () => {
    const { m, log } = connected();
    for (let i = 0; i < 500; i++) m.receive(Uint8Array.of(0x25, 0x63, 0x26, 0x0d, 0x0a));
    m.receive(Uint8Array.from(pkt(0x1e, 0x00, 55, 0, 50, 0x00, 0x03, 0, 0, 0, 0)));
    expect(m.malformed.unknownCommand).toBe(500);
    expect(m.nacks).toBe(500);
    expect(m.reference.hand).toBe(55);
    const logged = log.filter((l) => l.startsWith("unknown command"));
    expect(logged.length).toBe(15); // the first 10, then every 100th
    expect(logged.at(-1)).toBe(
      "unknown command: command 99 (25 63 26 0D 0A) [malformed input 500]",
    );
  });

  test("the dongle: unknown commands, con to nobody, dct with no hand, bytes with no hand", () => {
    const { m, replies, log } = machine();
    m.receive(Uint8Array.from(text("hello")));
    m.receive(Uint8Array.from(text("$$$bogus\r\ncon 5\r\ndct\r\n")));
    expect(replies()).toBe("Command failed\r\n".repeat(3));
    expect(m.malformed).toMatchObject({ noHand: 5, unknownDongleCommand: 1 });
    expect(log).toContain("con 5: no device 5 in the scan table");
    // A line that never ends is dropped, and the dongle still answers afterwards.
    m.receive(new Uint8Array(300).fill(0x41));
    m.receive(Uint8Array.from(text("\r\nscan\r\n")));
    expect(m.malformed.unknownDongleCommand).toBe(2);
    expect(replies().endsWith(scanReply(m.devices))).toBe(true);
  });
});

describe("mosaic simulate hannes's options", () => {
  test("checked, with what is wrong", () => {
    expect(hannesDongleSimulatorOptions({ port: "/tmp/d", names: "HannesL, HannesR" })).toEqual({
      path: "/tmp/d",
      names: ["HannesL", "HannesR"],
    });
    expect(hannesDongleSimulatorOptions({ port: "/tmp/d", verbose: true })).toEqual({
      path: "/tmp/d",
      verbose: true,
    });
    expect(() => hannesDongleSimulatorOptions({})).toThrow(/^--port PATH is required: .*socat pty/);
    expect(() => hannesDongleSimulatorOptions({ port: "/d", names: "a b" })).toThrow(
      "--names: a Hannes name is 1…32 letters, digits, '_', '.' or '-' (the scan table splits on spaces), not 'a b'",
    );
  });
});
