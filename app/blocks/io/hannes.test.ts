import { describe, expect, test } from "vitest";
import {
  createCatalog,
  EMPTY_SHAPE,
  Frame,
  loadPipeline,
  vectorShape,
  type IoBridges,
  type SerialOptions,
} from "../../engine";
import { BlockHarness } from "../../engine/testing";
import { HannesGUI } from "./hannes-gui";
import { HannesHand } from "./hannes-hand";
import {
  decodeHannesEmg,
  guiArv,
  guiRawEmg,
  packet,
  parseScanLine,
  simultRefPayload,
  toByte,
} from "./hannes-protocol";
import { HannesReceiver } from "./hannes-receiver";

const hex = (b: Uint8Array): string => Buffer.from(b).toString("hex");
const frame = (rows: number[][], t0 = 1) =>
  Frame.from(
    vectorShape(rows[0]!.length),
    rows.map((_, i) => t0 + i * 0.04),
    rows,
  );
/** Actuation in DOAs order: 6 fingers, F/E, U/R, P/S, elbows. */
const act = (o: Partial<Record<"tf" | "tr" | "mid" | "fe" | "ur" | "ps", number>>) => [
  o.tf ?? 0,
  o.tr ?? 0,
  0,
  o.mid ?? 0,
  0,
  0,
  o.fe ?? 50,
  o.ur ?? 50,
  o.ps ?? 50,
  0,
  0,
];

describe("Hannes formats", () => {
  test("bytes as C#'s (byte) cast made them: truncated, two's complement, clamped here", () => {
    expect([0, 99.9, 100, -50, -100, -0.5, 250, NaN].map((x) => toByte(x, -100, 100))).toEqual([
      0, 99, 100, 206, 156, 0, 100, 0,
    ]);
    expect(hex(packet([0]))).toBe("2500260d0a");
  });

  test("SimultRefControl: 30, 0, hand, P/S, F/E, 0, 3, thumb, 0, 0, 0", () => {
    expect(simultRefPayload([100, -100, 50, 40])).toEqual([30, 0, 100, 156, 50, 0, 3, 40, 0, 0, 0]);
  });

  test("scan table lines as the original parsed them", () => {
    expect(parseScanLine("  #  Con RSSI Address Name")).toBeNull();
    expect(parseScanLine("0 1 -52 001122334455 HannesL\r")).toEqual({
      con: 1,
      rssi: -52,
      address: "001122334455",
      name: "HannesL",
    });
    expect(parseScanLine("1 # 2 -60 0011223344AA HannesR")).toEqual({
      con: 2,
      rssi: -60,
      address: "0011223344AA",
      name: "HannesR",
    });
    expect(parseScanLine("Success\r")).toBeNull();
  });

  test("GUI raw EMG (signed bytes, padded) and ARV (float64 LE) datagrams; EMG decoding", () => {
    expect(hex(guiRawEmg([0.5, -0.5, 1, -1], 0, 4, 6))).toBe("2510" + "40c07f800000" + "260d0a");
    const a = guiArv([0.25], 0, 1, 16);
    expect(a.length).toBe(21);
    expect(new DataView(a.buffer).getFloat64(2, true)).toBe(0.25);
    expect(hex(a.subarray(10, 21))).toBe("0000000000000000260d0a");
    const out = new Float64Array(2);
    expect(decodeHannesEmg(Uint8Array.of(0x25, 16, 0x00, 0x80, 0xff, 0xff), 2, out)).toBe(true);
    expect(Array.from(out)).toEqual([0.5, 65535 / 65536]);
    expect(decodeHannesEmg(Uint8Array.of(0x25, 16, 0), 2, out)).toBe(false);
  });
});

function fakeUdp() {
  const sent: string[] = [];
  let onMessage: ((d: Uint8Array, from: { host: string; port: number }) => void) | undefined;
  const io: IoBridges = {
    udp: {
      open: (o) => {
        onMessage = o.onMessage;
        o.onReady?.({ host: "0.0.0.0", port: 11000 });
        return { send: (d) => sent.push(hex(d)), close: () => {} };
      },
    },
  };
  return { io, sent, deliver: (d: Uint8Array) => onMessage!(d, { host: "10.0.0.5", port: 4000 }) };
}

describe("HannesGUI", () => {
  test("three activation datagrams per control event; raw EMG and ARVs sized by the params", async () => {
    const udp = fakeUdp();
    const h = await BlockHarness.create(
      HannesGUI,
      { Port: 8889, RawEmgBytes: 8, ArvBytes: 64 },
      {
        inputs: [
          { shape: vectorShape(11), rate: 25 },
          { shape: vectorShape(8), rate: 200 },
          { shape: vectorShape(8), rate: 25 },
        ],
        io: udp.io,
      },
    );
    h.start();
    h.push(frame([act({ tf: 75.9, ps: 20, fe: 100 })]), 0);
    expect(udp.sent).toEqual(["250f004b260d0a", "250f0114260d0a", "250f0264260d0a"]);
    udp.sent.length = 0;
    h.push(frame([[0.5, 0, 0, 0, 0, 0, 0, -0.25]], 2), 1);
    expect(udp.sent).toEqual(["2510" + "40000000000000e0" + "260d0a"]);
    udp.sent.length = 0;
    h.push(frame([[1, 2, 3, 4, 5, 6, 7, 8]], 3), 2);
    expect(udp.sent[0]!.length).toBe(2 * 69);
    expect(h.text).toMatch(/3 activations, 1 raw EMG datagram, 1 ARV datagram/);
  });

  test("the older HannesArm form: [host, port] and a 12-prediction input", async () => {
    const catalog = createCatalog([HannesGUI]);
    const r = loadPipeline(
      "H: { Type: HannesGUI, Inputs: [H], Params: [ localhost, 8889 ] }\n",
      "p.yaml",
      catalog,
    );
    expect(r.spec!.blocks[0]!.params).toEqual({ Host: "localhost", Port: 8889, Input: "auto" });
    const udp = fakeUdp();
    const h = await BlockHarness.create(HannesGUI, r.spec!.blocks[0]!.params, {
      inputs: [{ shape: vectorShape(12), rate: 25 }],
      io: udp.io,
    });
    h.start();
    // power grasp + pronation: thumb flexion 100, P/S 100, F/E 50
    h.push(frame([[1, 1, 1, 1, 1, 1, 0, 0, 1, 0, 0, 0]]));
    expect(udp.sent).toEqual(["250f0064260d0a", "250f0164260d0a", "250f0232260d0a"]);
    await expect(
      BlockHarness.create(
        HannesGUI,
        { Port: 1, ArvBytes: 16 },
        {
          inputs: [
            { shape: vectorShape(11) },
            { shape: vectorShape(2) },
            { shape: vectorShape(8) },
          ],
        },
      ),
    ).rejects.toThrow(/8 values, 64 bytes, more than ArvBytes 16/);
  });
});

describe("HannesReceiver", () => {
  const datagram = (...v: number[]) => {
    const b = new Uint8Array(2 + 2 * v.length);
    b[0] = 0x25;
    b[1] = 16;
    v.forEach((x, i) => {
      b[2 + 2 * i] = x & 0xff;
      b[3 + 2 * i] = x >> 8;
    });
    return b;
  };

  test("paced by a timer: oldest sample first, at most MaxDelay waiting, the last repeated when none", async () => {
    const udp = fakeUdp();
    const h = await BlockHarness.create(
      HannesReceiver,
      { Port: 11000, Channels: 2, MaxDelay: 2 },
      { inputs: [{ shape: EMPTY_SHAPE, rate: 100, isTimer: true }], io: udp.io },
    );
    h.start();
    h.push(Frame.from(EMPTY_SHAPE, [0], [[]]));
    udp.deliver(datagram(0x8000, 0x4000));
    udp.deliver(datagram(0x1000, 0));
    udp.deliver(datagram(0x2000, 0)); // drops the oldest (MaxDelay 2)
    udp.deliver(Uint8Array.of(0x25, 16, 1)); // too short
    h.push(Frame.from(EMPTY_SHAPE, [1, 1.01, 1.02], [[], [], []]));
    expect(h.output().v).toEqual([
      [0, 0],
      [0x1000 / 65536, 0],
      [0x2000 / 65536, 0],
      [0x2000 / 65536, 0],
    ]);
    expect(h.text).toMatch(
      /4 datagrams, 1 dropped \(MaxDelay\), 2 ticks without a new sample, 1 malformed/,
    );
  });

  test("without a timer every datagram is an event; MOSAIC's [udpPort, numEMGs]", async () => {
    const udp = fakeUdp();
    const h = await BlockHarness.create(HannesReceiver, { Port: 11000 }, { io: udp.io });
    h.start();
    udp.deliver(datagram(1, 2, 3, 4, 5, 0xffff));
    expect(h.output().v).toEqual([[1, 2, 3, 4, 5, 0xffff].map((x) => x / 65536)]);
    const r = loadPipeline(
      "R: { Type: HannesReceiver, Params: [ 11000, 6 ] }\n",
      "p.yaml",
      createCatalog([HannesReceiver]),
    );
    expect(r.spec!.blocks[0]!.params).toMatchObject({ Port: 11000, Channels: 6, Host: "0.0.0.0" });
  });
});

/**
 * The Rehab Dongle and a Hannes hand, as the original's code expects them to answer: each write
 * is one command; replies are delivered at once.
 */
function fakeHannes(opts: { ack?: boolean; names?: string[] } = {}) {
  const written: string[] = [];
  const packets: number[][] = [];
  let opened: SerialOptions | undefined;
  let reply: (s: string | number[]) => void = () => {};
  const io: IoBridges = {
    serial: {
      list: async () => [],
      open: (o) => {
        opened = o;
        reply = (s) =>
          o.onData(
            typeof s === "string" ? Uint8Array.from(s, (c) => c.charCodeAt(0)) : Uint8Array.from(s),
          );
        o.onStatus("open");
        return {
          write: (d) => {
            const text = String.fromCharCode(...d);
            written.push(text);
            if (d[0] === 0x25) {
              packets.push(Array.from(d.subarray(1, d.length - 3)));
              if (d[1] === 0 && opts.ack !== false) reply("%\x02&\r\n");
            } else if (text === "scan\r\n") {
              reply("  #  Con RSSI Address      Name\r\n");
              (opts.names ?? ["HannesL"]).forEach((n, i) =>
                reply(`${i} ${i + 1} -5${i} 00112233445${i} ${n}\r\n`),
              );
              reply("Success\r\n");
            } else if (text.startsWith("con ")) {
              reply(`${text.trim()}\r\nSuccess\r\nSTREAM_MODE\r\n`);
            }
          },
          close: () => o.onStatus("closed"),
        };
      },
    },
  };
  return { io, written, packets, opened: () => opened };
}

async function hand(params: Record<string, unknown>, device = fakeHannes()) {
  const h = await BlockHarness.create(HannesHand, params, {
    inputs: [{ shape: vectorShape(11), rate: 25 }],
    io: device.io,
  });
  h.start();
  return { h, device };
}

/** Fires the pending one-shots (the handshake's waits) until none is left. */
function runHandshake(h: BlockHarness): number {
  let k = 0;
  while (h.fireOneShot()) k++;
  return k;
}

describe("HannesHand", () => {
  test("the handshake of the original, then one SimultRefControl packet per control event", async () => {
    const { h, device } = await hand({ Port: "/dev/ttyACM0" });
    expect(device.opened()).toMatchObject({
      path: "/dev/ttyACM0",
      baudRate: 115200,
      parity: "none",
    });
    runHandshake(h);
    expect(h.text).toBe(
      "HannesL on /dev/ttyACM0, actuation vector (ControlAlgorithm): 0 references sent",
    );
    expect(device.written.slice(0, 3)).toEqual(["$$$", "scan\r\n", "con 1\r\n"]);
    expect(device.packets).toEqual([
      [0], // EnterCMDMode (the ping)
      [14, 0, 0x64], // RefControl JOINT_SET: thumb, wrist F/E, wrist P/S
      [14, 5, 3], // RefControl CONTROL_MODE: UNITY
      [1], // ExitCMDMode: stream
    ]);
    device.packets.length = 0;
    h.push(frame([act({ mid: 80, ps: 100, fe: 30, tr: 0 })]));
    expect(device.packets).toEqual([[30, 0, 80, 156, 30, 0, 3, 100, 0, 0, 0]]);
    expect(h.output("reference").v).toEqual([[80, -100, 30, 100]]);
    // Stop: neutral pose, command mode, then the dongle disconnects.
    device.packets.length = 0;
    h.instance.stop?.();
    expect(device.packets).toEqual([[30, 0, 0, 0, 80, 0, 3, 0, 0, 0, 0], [0]]);
    expect(device.written.slice(-2)).toEqual(["$$$", "dct\r\n"]);
  });

  test("chooses Device by name; says why when the scan finds nothing or the hand does not answer", async () => {
    const two = fakeHannes({ names: ["HannesL", "HannesR"] });
    const { h } = await hand({ Device: "HannesR" }, two);
    runHandshake(h);
    expect(two.written).toContain("con 2\r\n");
    expect(h.text).toMatch(/^HannesR on COM50/);

    const { h: h2 } = await hand({ Device: "Nope" }, fakeHannes());
    runHandshake(h2);
    expect(h2.text).toBe("COM50: 'Nope' not found; the scan found HannesL");
    expect(h2.warnings).toHaveLength(1);

    const { h: h3 } = await hand({}, fakeHannes({ ack: false }));
    runHandshake(h3);
    expect(h3.text).toMatch(/HannesL did not acknowledge/);
  });

  test("Connect: false waits for the connect action; references flow out before the hand is there", async () => {
    const { h, device } = await hand({ Connect: false });
    expect(h.text).toBe("COM50 open; press connect to find the Hannes");
    h.push(frame([act({ mid: 10 })]));
    expect(device.packets).toEqual([]);
    expect(h.output("reference").v).toEqual([[10, 0, 50, 100]]);
    expect(h.instance.actions!.connect!.run()).toBe("scanning for a Hannes");
    runHandshake(h);
    expect(h.text).toMatch(/^HannesL on COM50/);
  });

  test("MOSAIC's [COMport] or no Params", () => {
    const catalog = createCatalog([HannesHand]);
    const r = loadPipeline(
      'H: { Type: HannesHand, Inputs: [H], Params: [ "COM7" ] }\nI: { Type: HannesHand, Inputs: [H] }\n',
      "p.yaml",
      catalog,
    );
    expect(r.spec!.blocks.map((b) => (b.params as { Port: string }).Port)).toEqual([
      "COM7",
      "COM50",
    ]);
  });
});
