/**
 * The Hannes GUI simulator: datagrams built here from docs/protocols.md ("Hannes", HannesGUI)
 * sent over real loopback UDP, decoded exactly; malformed ones counted; the state line; a taken
 * port; the options. HannesGUI against it is tests/integration/hannes-simulate.test.ts.
 */
import { createSocket } from "node:dgram";
import { afterEach, describe, expect, test } from "vitest";
import {
  decodeGuiDatagram,
  hannesGuiSimulatorOptions,
  startHannesGuiSimulator,
  type HannesGuiSimulator,
} from "./hannes-gui-simulator";

const framed = (kind: number, body: number[]): Uint8Array =>
  Uint8Array.from([0x25, kind, ...body, 0x26, 0x0d, 0x0a]);

function arv(values: number[]): Uint8Array {
  const body = new Uint8Array(8 * values.length);
  const dv = new DataView(body.buffer);
  values.forEach((v, i) => dv.setFloat64(8 * i, v, true));
  return framed(32, [...body]);
}

const sims: HannesGuiSimulator[] = [];
afterEach(async () => {
  for (const s of sims.splice(0)) await s.close();
});

describe("decoding", () => {
  test("activation, raw EMG (signed bytes), ARV (float64 LE)", () => {
    expect(decodeGuiDatagram(framed(15, [1, 63]))).toEqual({
      kind: "activation",
      joint: 1,
      value: 63,
    });
    expect(decodeGuiDatagram(framed(16, [0, 127, 128, 255, 0xce]))).toEqual({
      kind: "raw",
      values: [0, 127, -128, -1, -50],
    });
    expect(decodeGuiDatagram(arv([0.125, -3.5, 1e-9]))).toEqual({
      kind: "arv",
      values: [0.125, -3.5, 1e-9],
    });
  });

  test("malformed: kind and reason", () => {
    const faults = [
      Uint8Array.of(0x25, 15, 0, 1),
      Uint8Array.of(0x24, 15, 0, 1, 0x26, 0x0d, 0x0a),
      framed(15, [0]),
      framed(15, [3, 10]),
      framed(15, [0, 101]),
      framed(32, [1, 2, 3]),
      framed(99, []),
    ].map(decodeGuiDatagram);
    expect(faults.map((d) => (d.kind === "malformed" ? d.fault : d.kind))).toEqual([
      "notFramed",
      "notFramed",
      "badLength",
      "badValue",
      "badValue",
      "badLength",
      "unknownKind",
    ]);
    expect(faults[3]).toMatchObject({
      why: "activation of joint 3 to 10 (joints 0…2, values 0…100)",
    });
  });
});

describe("on loopback UDP", () => {
  test("every datagram decoded in order; the state; malformed counted", async () => {
    const lines: string[] = [];
    const sim = await startHannesGuiSimulator({
      port: 0,
      record: true,
      log: (l) => lines.push(l),
    });
    sims.push(sim);
    const tx = createSocket("udp4");
    const sent = [
      framed(15, [0, 40]),
      framed(15, [1, 50]),
      framed(15, [2, 75]),
      framed(16, [1, 2, 0xff]),
      arv([0.5, 0.25]),
      framed(7, [1]),
    ];
    for (const d of sent) {
      await new Promise<void>((r) => tx.send(d, sim.port, "127.0.0.1", () => r()));
    }
    await sim.waitFor(() => sim.received.length === sent.length, "datagrams");
    tx.close();
    expect(sim.received).toEqual([
      { kind: "activation", joint: 0, value: 40 },
      { kind: "activation", joint: 1, value: 50 },
      { kind: "activation", joint: 2, value: 75 },
      { kind: "raw", values: [1, 2, -1] },
      { kind: "arv", values: [0.5, 0.25] },
      { kind: "malformed", fault: "unknownKind", why: "kind 7 (15, 16 and 32 known)" },
    ]);
    expect(sim.stateText()).toBe(
      "hand 40 · wrist P/S 50 · wrist F/E 75 · raw EMG [3] 1 2 -1 (max |x| 2) · ARV [2] 0.500 0.250 (max |x| 0.500) · 5 datagrams · malformed: 1 unknown kind",
    );
    await sim.close();
    // The last state is printed (at most four lines a second, the last one always).
    expect(lines.at(-1)).toBe(sim.stateText());
    expect(lines).toContain("malformed datagram 1: unknown kind: kind 7 (15, 16 and 32 known)");
  });

  test("a taken port: one error that says so (exit status 1 from the CLI)", async () => {
    const first = await startHannesGuiSimulator({ port: 0 });
    sims.push(first);
    const e = await startHannesGuiSimulator({ port: first.port }).catch((x: unknown) => x);
    expect(e).toBeInstanceOf(Error);
    expect((e as Error).message).toBe(
      `UDP 127.0.0.1:${first.port} is in use (another Hannes GUI?)`,
    );
    expect((e as { exitCode?: number }).exitCode).toBe(1);
  });
});

describe("mosaic simulate hannes-gui's options", () => {
  test("checked, with what is wrong", () => {
    expect(hannesGuiSimulatorOptions({})).toEqual({});
    expect(hannesGuiSimulatorOptions({ port: "9000", host: "0.0.0.0" })).toEqual({
      port: 9000,
      host: "0.0.0.0",
    });
    expect(() => hannesGuiSimulatorOptions({ port: "70000" })).toThrow(
      "--port must be a whole number in 0…65535, not '70000'",
    );
    expect(() => hannesGuiSimulatorOptions({ port: "x" })).toThrow(
      "--port must be a whole number (0…65535), not 'x'",
    );
  });
});
