import { describe, expect, test } from "vitest";
import type { BleAdapterState, BleBridge, BlePeripheral } from "../app/engine/io";
import { bleHub, bleProxy, type BleReply, type BleRequest } from "./ble-proxy";

const settle = (): Promise<void> => new Promise((r) => setTimeout(r, 0));

/** A real-bridge stand-in on the main thread side, recording what the hub asks of it. */
function fakeBridge() {
  const log: string[] = [];
  const dev = {
    state: (_s: BleAdapterState, _m?: string) => {},
    found: (_p: BlePeripheral) => {},
    scanError: (_m: string) => {},
    data: (_d: Uint8Array) => {},
    lose: (_r: string) => {},
  };
  const bridge: BleBridge = {
    watchState(fn) {
      dev.state = fn;
      fn("unavailable", "no Bluetooth adapter (EAFNOSUPPORT)");
      return { close: () => log.push("unwatch") };
    },
    scan(o) {
      log.push(`scan ${o.services.join(",")}`);
      dev.found = o.onFound;
      dev.scanError = o.onError;
      return { stop: () => log.push("stop scan") };
    },
    async connect(address, onDisconnect) {
      log.push(`connect ${address}`);
      if (address === "bad") throw new Error("no answer within 10 s");
      dev.lose = onDisconnect;
      return {
        address,
        discover: async (s) => {
          log.push(`discover ${s.join(",")}`);
          return [{ service: "0005", uuid: "0105", properties: ["notify"] }];
        },
        subscribe: async (s, c, onData) => {
          log.push(`subscribe ${s}/${c}`);
          dev.data = onData;
        },
        write: async (s, c, d, w) => {
          log.push(`write ${s}/${c} ${Buffer.from(d).toString("hex")} ${w}`);
        },
        disconnect: () => log.push(`disconnect ${address}`),
      };
    },
  };
  return { bridge, dev, log };
}

/** Proxy and hub joined as postMessage would join them (structured clones). */
function link(real: BleBridge) {
  const ends: { hub?: ReturnType<typeof bleHub> } = {};
  const proxy = bleProxy((m: BleRequest) => ends.hub!.receive(structuredClone(m)));
  ends.hub = bleHub((m: BleReply) => proxy.receive(structuredClone(m)), real);
  return { proxy, hub: ends.hub };
}

describe("BLE proxy (worker) ↔ hub (main thread)", () => {
  test("adapter state, scan, connect, discover, notifications, writes, a lost link", async () => {
    const { bridge, dev, log } = fakeBridge();
    const { proxy } = link(bridge);
    const b = proxy.bridge;

    const states: string[] = [];
    const w = b.watchState((s, m) => states.push(m ? `${s}: ${m}` : s));
    expect(states).toEqual(["unavailable: no Bluetooth adapter (EAFNOSUPPORT)"]);
    dev.state("poweredOn");
    expect(states.at(-1)).toBe("poweredOn");

    const found: BlePeripheral[] = [];
    const errors: string[] = [];
    const scan = b.scan({
      services: ["d506"],
      onFound: (p) => found.push(p),
      onError: (m) => errors.push(m),
    });
    dev.found({ address: "aa:bb", services: ["d506"], rssi: -50 });
    dev.scanError("scan failed: busy");
    expect(found).toEqual([{ address: "aa:bb", services: ["d506"], rssi: -50 }]);
    expect(errors).toEqual(["scan failed: busy"]);
    scan.stop();
    scan.stop();

    const lost: string[] = [];
    const c = await b.connect("aa:bb", (r) => lost.push(r));
    expect(c.address).toBe("aa:bb");
    expect(await c.discover(["0005"])).toEqual([
      { service: "0005", uuid: "0105", properties: ["notify"] },
    ]);
    const data: number[][] = [];
    await c.subscribe("0005", "0105", (d) => data.push([...d]));
    const big = new Uint8Array(40);
    big.set([7, 8, 9], 30);
    dev.data(big.subarray(30, 33));
    expect(data).toEqual([[7, 8, 9]]);
    await c.write("0001", "0401", Uint8Array.of(9, 1, 1));
    expect(log).toEqual([
      "scan d506",
      "stop scan",
      "connect aa:bb",
      "discover 0005",
      "subscribe 0005/0105",
      "write 0001/0401 090101 false",
    ]);
    // The link is lost on the main thread: the worker hears it once, and no more data.
    dev.lose("out of range");
    expect(lost).toEqual(["out of range"]);
    dev.data(Uint8Array.of(1));
    expect(data).toHaveLength(1);
    await expect(c.write("0001", "0401", Uint8Array.of(1))).rejects.toThrow("not connected");
    c.disconnect();
    expect(log.filter((l) => l.startsWith("disconnect"))).toEqual([]);
    w.close();
    expect(log.at(-1)).toBe("unwatch");
  });

  test("a failed connection rejects; disconnect and closeAll reach the real bridge", async () => {
    const { bridge, log } = fakeBridge();
    const { proxy, hub } = link(bridge);
    await expect(proxy.bridge.connect("bad", () => {})).rejects.toThrow("no answer within 10 s");
    const c = await proxy.bridge.connect("cc:dd", () => {});
    c.disconnect();
    c.disconnect();
    expect(log.filter((l) => l.startsWith("disconnect"))).toEqual(["disconnect cc:dd"]);
    await proxy.bridge.connect("ee:ff", () => {});
    proxy.bridge.watchState(() => {});
    proxy.bridge.scan({ services: [], onFound: () => {}, onError: () => {} });
    hub.closeAll();
    expect(log.slice(-3)).toEqual(["unwatch", "stop scan", "disconnect ee:ff"]);
  });

  test("a connection the worker dropped while it was being made is closed when it completes", async () => {
    const { bridge, log } = fakeBridge();
    const replies: BleReply[] = [];
    const hub = bleHub((m) => replies.push(m), bridge);
    hub.receive({ type: "ble", op: "connect", id: 1, address: "aa:bb" });
    hub.receive({ type: "ble", op: "disconnect", conn: 1 });
    await settle();
    expect(log).toEqual(["connect aa:bb", "disconnect aa:bb"]);
    expect(replies).toEqual([
      { type: "ble", op: "result", id: 1, ok: false, error: "disconnected" },
    ]);
  });
});
