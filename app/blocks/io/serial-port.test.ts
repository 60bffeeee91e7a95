import { describe, expect, test } from "vitest";
import { vectorShape, type SerialBridge, type SerialStatus } from "../../engine";
import { BlockHarness } from "../../engine/testing";
import { vectors } from "../../../tests/support/blocks";
import { SerialPort } from "./serial-port";
import { structEncoder } from "./serial-framing";

const ascii = (s: string): Uint8Array => Uint8Array.from(s, (c) => c.charCodeAt(0));

/** A bridge whose one port the test drives: data in, status changes, writes recorded. */
function fakeBridge() {
  const port = {
    opened: [] as { path: string; baudRate: number; reconnectMs: number; parity: string }[],
    written: [] as Uint8Array[],
    closed: 0,
    data: (_b: Uint8Array) => {},
    status: (_s: SerialStatus, _m?: string) => {},
  };
  const bridge: SerialBridge = {
    open(o) {
      port.opened.push({
        path: o.path,
        baudRate: o.baudRate,
        reconnectMs: o.reconnectMs,
        parity: o.parity,
      });
      port.data = o.onData;
      port.status = o.onStatus;
      o.onStatus("open");
      return {
        write: (d) => port.written.push(d.slice()),
        close: () => {
          port.closed++;
          o.onStatus("closed");
        },
      };
    },
    list: async () => [],
  };
  return { bridge, port };
}

describe("SerialPort", () => {
  test("lines in become events stamped with arrival time; input vectors are written as lines", async () => {
    const { bridge, port } = fakeBridge();
    const h = await BlockHarness.create(
      SerialPort,
      { Path: "/dev/ttyACM0", Channels: 2, BaudRate: 9600, Parity: "even", Reconnect: 0.5 },
      { io: { serial: bridge }, inputs: [{ shape: vectorShape(2), rate: 10 }] },
    );
    h.start();
    expect(port.opened).toEqual([
      { path: "/dev/ttyACM0", baudRate: 9600, reconnectMs: 500, parity: "even" },
    ]);
    h.clock = 1.5;
    port.data(ascii("1,2\n3,"));
    h.clock = 1.6;
    port.data(ascii("4\n"));
    expect(h.output().t).toEqual([1.5, 1.6]);
    expect(h.output().v).toEqual([
      [1, 2],
      [3, 4],
    ]);
    expect(h.text).toBe("/dev/ttyACM0 open @ 9600 Bd · 2 frames");
    h.push(
      vectors(
        [2, 2.1],
        [
          [0.5, -1],
          [7, 8],
        ],
      ),
    );
    expect(port.written.map((b) => String.fromCharCode(...b))).toEqual(["0.5,-1\n", "7,8\n"]);
    expect(h.text).toBe("/dev/ttyACM0 open @ 9600 Bd · 2 frames · 2 written");
  });

  test("malformed data is counted and warned, an unplug and a reconnect show in the status", async () => {
    const { bridge, port } = fakeBridge();
    const h = await BlockHarness.create(
      SerialPort,
      { Path: "COM3", Channels: 1 },
      { io: { serial: bridge } },
    );
    h.start();
    port.data(ascii("1\nnope\n2\n"));
    expect(h.output().v).toEqual([[1], [2]]);
    expect(h.text).toMatch(/1 malformed \(last: "nope" is not a number/);
    expect(h.warnings).toHaveLength(1);
    port.data(ascii("12"));
    port.status("error", "disconnected (unplugged?); retrying every 1 s");
    expect(h.text).toMatch(/^COM3: disconnected \(unplugged\?\); retrying every 1 s/);
    // A partial line from before the unplug is not glued to the first line after it.
    port.status("opening");
    expect(h.text).toMatch(/^opening COM3…/);
    port.status("open");
    port.data(ascii("5\n"));
    expect(h.output().v.at(-1)).toEqual([5]);
    h.instance.stop?.();
    expect(port.closed).toBe(1);
    expect(h.text).toMatch(/^COM3 closed/);
    h.instance.dispose?.();
    h.instance.dispose?.();
  });

  test("reset drops a partial line and zeroes every count; the port stays open", async () => {
    const { bridge, port } = fakeBridge();
    const h = await BlockHarness.create(
      SerialPort,
      { Path: "COM4", Channels: 1 },
      { io: { serial: bridge }, inputs: [{ shape: vectorShape(1), rate: 10 }] },
    );
    h.start();
    port.data(ascii("1\nnope\n2\n3"));
    h.push(vectors([1], [[4]]));
    expect(h.text).toMatch(/^COM4 open @ 115200 Bd · 2 frames · 1 written · 1 malformed/);
    h.instance.reset?.();
    expect(h.text).toBe("COM4 open @ 115200 Bd · 0 frames");
    expect(port.closed).toBe(0);
    // The "3" before the reset is not glued to the next line.
    port.data(ascii("5\n"));
    expect(h.output().v.at(-1)).toEqual([5]);
    expect(h.text).toBe("COM4 open @ 115200 Bd · 1 frames");
  });

  test("binary frames decode; writes use the same framing", async () => {
    const { bridge, port } = fakeBridge();
    const framing = {
      Framing: "binary",
      Fields: ["u8", "f32"],
      Sync: [0xa5],
      Checksum: "xor8",
    } as const;
    const h = await BlockHarness.create(
      SerialPort,
      { Path: "/dev/ttyUSB0", ...framing },
      { io: { serial: bridge }, inputs: [{ shape: vectorShape(2), rate: 10 }] },
    );
    h.start();
    const enc = structEncoder({
      fields: ["u8", "f32"],
      sync: [0xa5],
      checksum: "xor8",
      littleEndian: true,
    });
    port.data(Uint8Array.from([...enc.encode([7, 0.5]), ...enc.encode([8, -2])]));
    expect(h.output().v).toEqual([
      [7, 0.5],
      [8, -2],
    ]);
    h.push(vectors([0], [[9, 1.5]]));
    expect(port.written).toEqual([enc.encode([9, 1.5])]);
  });

  test("without a serial bridge (browser build) it says so and the block still runs", async () => {
    const h = await BlockHarness.create(SerialPort, { Path: "/dev/ttyUSB0", Channels: 3 });
    h.start();
    expect(h.text).toMatch(/not available here \(browser build\)/);
    h.instance.stop?.();
  });

  test("framing params are checked with the parameter named", async () => {
    await expect(BlockHarness.create(SerialPort, { Path: "x" })).rejects.toThrow(
      /lines framing needs Channels/,
    );
    await expect(BlockHarness.create(SerialPort, { Path: "x", Framing: "binary" })).rejects.toThrow(
      /binary framing needs Fields/,
    );
    await expect(
      BlockHarness.create(SerialPort, {
        Path: "x",
        Framing: "binary",
        Fields: ["u8"],
        Channels: 2,
      }),
    ).rejects.toThrow(/Channels is 2 but Fields lists 1 values/);
    await expect(
      BlockHarness.create(
        SerialPort,
        { Path: "x", Framing: "binary", Fields: ["u8"] },
        { inputs: [{ shape: vectorShape(3), rate: 1 }] },
      ),
    ).rejects.toThrow(/carries 3 values per event, but a binary frame holds 1 Fields/);
    await expect(
      BlockHarness.create(SerialPort, { Path: "x", Channels: 1, Parity: "weird" }),
    ).rejects.toThrow(/Parity/);
  });
});
