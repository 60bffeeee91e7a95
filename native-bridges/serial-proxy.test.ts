import { describe, expect, test } from "vitest";
import type { SerialBridge, SerialStatus } from "../app/engine/io";
import { serialHub, serialProxy, type SerialReply, type SerialRequest } from "./serial-proxy";

describe("serial proxy (worker) ↔ hub (main thread)", () => {
  test("open, data, status, write, list and close cross the message boundary", async () => {
    const opened: string[] = [];
    const writes: number[][] = [];
    let deliver: ((d: Uint8Array) => void) | undefined;
    let report: ((s: SerialStatus, m?: string) => void) | undefined;
    let closes = 0;
    const real: SerialBridge = {
      open(o) {
        opened.push(`${o.path}@${o.baudRate}/${o.reconnectMs}`);
        deliver = o.onData;
        report = o.onStatus;
        o.onStatus("open");
        return { write: (d) => writes.push([...d]), close: () => closes++ };
      },
      list: async () => [{ path: "/dev/ttyUSB0" }],
    };
    // Messages go through structuredClone, as postMessage would copy them.
    const link: { hub?: ReturnType<typeof serialHub> } = {};
    const proxy = serialProxy((m: SerialRequest) => link.hub!.receive(structuredClone(m)));
    link.hub = serialHub((m: SerialReply) => proxy.receive(structuredClone(m)), real);

    const statuses: string[] = [];
    const data: number[][] = [];
    const h = proxy.bridge.open({
      path: "/dev/ttyACM0",
      baudRate: 9600,
      dataBits: 8,
      stopBits: 1,
      parity: "none",
      reconnectMs: 500,
      onData: (d) => data.push([...d]),
      onStatus: (s, m) => statuses.push(m ? `${s}: ${m}` : s),
    });
    expect(opened).toEqual(["/dev/ttyACM0@9600/500"]);
    expect(statuses).toEqual(["open"]);
    const big = new Uint8Array(100);
    big.set([1, 2, 3], 10);
    deliver!(big.subarray(10, 13));
    expect(data).toEqual([[1, 2, 3]]);
    report!("error", "disconnected (unplugged?); retrying every 0.5 s");
    expect(statuses.at(-1)).toBe("error: disconnected (unplugged?); retrying every 0.5 s");
    h.write(Uint8Array.of(9, 8));
    expect(writes).toEqual([[9, 8]]);
    expect(await proxy.bridge.list()).toEqual([{ path: "/dev/ttyUSB0" }]);
    h.close();
    expect(closes).toBe(1);
    expect(statuses.at(-1)).toBe("closed");
    // Nothing reaches a closed handle; closing twice is harmless.
    deliver!(Uint8Array.of(7));
    h.write(Uint8Array.of(1));
    h.close();
    expect(data).toHaveLength(1);
    expect(writes).toHaveLength(1);
  });

  test("closeAll closes every port a worker left open", () => {
    let closes = 0;
    const real: SerialBridge = {
      open: () => ({ write: () => {}, close: () => closes++ }),
      list: async () => [],
    };
    const hub = serialHub(() => {}, real);
    const options = {
      path: "a",
      baudRate: 1,
      dataBits: 8,
      stopBits: 1,
      parity: "none",
      reconnectMs: 0,
    } as const;
    hub.receive({ type: "serial", op: "open", id: 1, options });
    hub.receive({ type: "serial", op: "open", id: 2, options: { ...options, path: "b" } });
    hub.closeAll();
    expect(closes).toBe(2);
  });
});
