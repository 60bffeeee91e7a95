/**
 * The noble bridge: on this machine (no Bluetooth adapter, no Bluetooth in the kernel) it must
 * report the missing adapter cleanly; with an injected fake noble, scanning, connecting,
 * notifications, writes and a lost link go through noble's API as expected.
 */
import { EventEmitter } from "node:events";
import { existsSync, readFileSync } from "node:fs";
import { createRequire } from "node:module";
import { describe, expect, test } from "vitest";
import type { BleAdapterState, BlePeripheral } from "../app/engine/io";
import {
  createBleBridge,
  describeBleError,
  loadNoble,
  type NobleCharacteristic,
  type NobleLike,
  type NoblePeripheral,
} from "./ble";

const require = createRequire(import.meta.url);
const nobleLoads = ((): boolean => {
  try {
    require("@abandonware/noble");
    return true;
  } catch {
    return false;
  }
})();

describe.skipIf(nobleLoads)("the real noble where there is no Bluetooth adapter", () => {
  test("loading reports the reason instead of throwing", () => {
    const r = loadNoble();
    expect("error" in r && r.error).toMatch(/^no Bluetooth adapter \(/);
  });

  test("the bridge reports `unavailable` with the reason; scan and connect fail cleanly", async () => {
    const bridge = createBleBridge();
    const states: string[] = [];
    const w = bridge.watchState((s, m) => states.push(`${s}: ${m}`));
    expect(states).toHaveLength(1);
    expect(states[0]).toMatch(/^unavailable: no Bluetooth adapter \(.*EAFNOSUPPORT|ENODEV/);
    const errors: string[] = [];
    const scan = bridge.scan({ services: [], onFound: () => {}, onError: (m) => errors.push(m) });
    expect(errors).toEqual([states[0]!.replace(/^unavailable: /, "")]);
    scan.stop();
    await expect(bridge.connect("aa:bb:cc:dd:ee:ff", () => {})).rejects.toThrow(
      /no Bluetooth adapter/,
    );
    w.close();
  });
});

describe("why noble runs on the host's main thread", () => {
  const source = "node_modules/@abandonware/bluetooth-hci-socket/src/BluetoothHciSocket.cpp";
  test.skipIf(!existsSync(source))(
    "the Linux HCI binding polls its socket on the default (main thread's) libuv loop",
    () => {
      // If this changes, noble may be able to run in an engine worker: see ble.ts.
      expect(readFileSync(source, "utf8")).toMatch(/uv_poll_init\(uv_default_loop\(\)/);
    },
  );
});

describe("describeBleError", () => {
  test("names the usual causes", () => {
    expect(
      describeBleError(
        Object.assign(new Error("EAFNOSUPPORT, Address family not supported by protocol"), {
          code: "EAFNOSUPPORT",
        }),
      ),
    ).toBe(
      "no Bluetooth adapter (this system has no Bluetooth support: EAFNOSUPPORT, Address family not supported by protocol)",
    );
    expect(describeBleError(new Error("ENODEV, No such device"))).toBe(
      "no Bluetooth adapter (ENODEV, No such device)",
    );
    expect(describeBleError(new Error("EPERM, Operation not permitted"))).toMatch(
      /^no permission to use the Bluetooth adapter .*CAP_NET_RAW/,
    );
    expect(
      describeBleError(
        Object.assign(new Error("Cannot find module 'x'"), { code: "MODULE_NOT_FOUND" }),
      ),
    ).toMatch(/noble module is not installed/);
  });
});

/** A fake of noble and one Myo-like peripheral. */
function fakeNoble() {
  const n = new EventEmitter() as EventEmitter & NobleLike & { scanning: unknown[] };
  (n as { state: string }).state = "unknown";
  n.scanning = [];
  n.startScanningAsync = async (services?: string[], dup?: boolean) => {
    n.scanning.push(["start", services, dup]);
  };
  n.stopScanningAsync = async () => {
    n.scanning.push(["stop"]);
  };
  const written: string[] = [];
  const char = (uuid: string, props: string[]) => {
    const c = new EventEmitter() as EventEmitter & NobleCharacteristic & { subscribed: boolean };
    Object.assign(c, { uuid, properties: props, subscribed: false });
    c.subscribeAsync = async () => {
      c.subscribed = true;
    };
    c.writeAsync = async (data: Buffer, withoutResponse: boolean) => {
      written.push(`${uuid} ${data.toString("hex")} ${withoutResponse}`);
    };
    return c;
  };
  const emg = char("d5060105a904deb947482c7f4a124842", ["notify"]);
  const cmd = char("d5060401a904deb947482c7f4a124842", ["write"]);
  const p = new EventEmitter() as EventEmitter & NoblePeripheral & { calls: string[] };
  Object.assign(p, {
    id: "aabbccddeeff",
    address: "AA:BB:CC:DD:EE:FF",
    rssi: -60,
    advertisement: { localName: "Myo", serviceUuids: ["d5060001a904deb947482c7f4a124842"] },
    calls: [],
  });
  p.connectAsync = async () => {
    p.calls.push("connect");
  };
  p.disconnectAsync = async () => {
    p.calls.push("disconnect");
  };
  p.discoverSomeServicesAndCharacteristicsAsync = async (services: string[]) => {
    p.calls.push(`discover ${services.join(",")}`);
    return {
      services: [
        { uuid: "d5060005a904deb947482c7f4a124842", characteristics: [emg] },
        { uuid: "d5060001a904deb947482c7f4a124842", characteristics: [cmd] },
      ],
    };
  };
  const other = new EventEmitter() as EventEmitter & NoblePeripheral;
  Object.assign(other, {
    id: "0102",
    address: "01:02:03:04:05:06",
    advertisement: { serviceUuids: ["180f"] },
  });
  return { n, p, other, emg, cmd, written };
}

describe("the noble bridge on a fake noble", () => {
  test("states, a shared scan filtered by service, connect, notifications, writes, disconnect", async () => {
    const { n, p, other, emg, written } = fakeNoble();
    let loads = 0;
    const bridge = createBleBridge({
      load: () => {
        loads++;
        return { noble: n };
      },
    });
    const states: BleAdapterState[] = [];
    bridge.watchState((s) => states.push(s));
    expect(loads).toBe(1);
    const found: BlePeripheral[] = [];
    const found2: string[] = [];
    // Dashes and upper case are accepted.
    const s1 = bridge.scan({
      services: ["D5060001-A904-DEB9-4748-2C7F4A124842"],
      onFound: (x) => found.push(x),
      onError: () => {},
    });
    // Not scanning before the adapter is on.
    expect(n.scanning).toEqual([]);
    n.emit("stateChange", "poweredOn");
    expect(states).toEqual(["unknown", "poweredOn"]);
    expect(n.scanning).toEqual([["start", [], true]]);
    n.emit("discover", other);
    n.emit("discover", p);
    n.emit("discover", p); // duplicates are reported once per scan
    expect(found).toEqual([
      {
        address: "aa:bb:cc:dd:ee:ff",
        name: "Myo",
        rssi: -60,
        services: ["d5060001a904deb947482c7f4a124842"],
      },
    ]);
    // A second scan sees the armband when it advertises again; one noble scan serves both.
    const s2 = bridge.scan({
      services: [],
      onFound: (x) => found2.push(x.address),
      onError: () => {},
    });
    n.emit("discover", p);
    expect(found2).toEqual(["aa:bb:cc:dd:ee:ff"]);
    s1.stop();
    expect(n.scanning).toHaveLength(1);
    s2.stop();
    expect(n.scanning).toEqual([["start", [], true], ["stop"]]);

    const lost: string[] = [];
    const c = await bridge.connect("AA-BB-CC-DD-EE-FF", (r) => lost.push(r));
    const chars = await c.discover(["d5060005-a904-deb9-4748-2c7f4a124842"]);
    expect(p.calls).toEqual(["connect", "discover d5060005a904deb947482c7f4a124842"]);
    expect(chars.map((x) => `${x.service.slice(4, 8)}/${x.uuid.slice(4, 8)}`)).toEqual([
      "0005/0105",
      "0001/0401",
    ]);
    const data: number[][] = [];
    await c.subscribe("d5060005a904deb947482c7f4a124842", "d5060105a904deb947482c7f4a124842", (d) =>
      data.push([...d]),
    );
    const pool = Buffer.alloc(64);
    pool.set([1, 2, 3], 20);
    emg.emit("data", pool.subarray(20, 23), true);
    expect(data).toEqual([[1, 2, 3]]);
    await c.write(
      "d5060001a904deb947482c7f4a124842",
      "d5060401a904deb947482c7f4a124842",
      Uint8Array.of(9, 1, 1),
    );
    expect(written).toEqual(["d5060401a904deb947482c7f4a124842 090101 false"]);
    await expect(
      c.write("d5060001a904deb947482c7f4a124842", "ffff", Uint8Array.of(1)),
    ).rejects.toThrow(/not discovered/);
    // The link is lost: reported once, notifications stop.
    p.emit("disconnect", "connection timeout");
    expect(lost).toEqual(["connection timeout"]);
    emg.emit("data", Buffer.from([4]), true);
    expect(data).toHaveLength(1);
    c.disconnect();
    expect(p.calls).not.toContain("disconnect");
  });

  test("a disconnect asked for is not reported as lost; unknown peripherals and failed init are errors", async () => {
    const { n, p } = fakeNoble();
    const bridge = createBleBridge({ load: () => ({ noble: n }) });
    const states: string[] = [];
    bridge.watchState((s, m) => states.push(m ? `${s}: ${m}` : s));
    await expect(bridge.connect("aa:bb:cc:dd:ee:ff", () => {})).rejects.toThrow(
      /has not been found by a scan/,
    );
    n.emit("stateChange", "poweredOn");
    bridge.scan({ services: [], onFound: () => {}, onError: () => {} });
    n.emit("discover", p);
    const lost: string[] = [];
    const c = await bridge.connect("aa:bb:cc:dd:ee:ff", (r) => lost.push(r));
    c.disconnect();
    p.emit("disconnect");
    expect(lost).toEqual([]);
    expect(p.calls).toContain("disconnect");
    // Noble reports a failed adapter initialisation as a warning.
    n.emit("warning", "Initialization of USB device failed: ENODEV, No such device");
    expect(states.at(-1)).toBe("unavailable: no Bluetooth adapter (ENODEV, No such device)");
  });

  test("a connection that does not answer times out", async () => {
    const { n, p } = fakeNoble();
    p.connectAsync = () => new Promise(() => {});
    let cancelled = 0;
    p.cancelConnect = () => cancelled++;
    const bridge = createBleBridge({ load: () => ({ noble: n }), connectTimeoutMs: 20 });
    bridge.watchState(() => {});
    n.emit("stateChange", "poweredOn");
    bridge.scan({ services: [], onFound: () => {}, onError: () => {} });
    n.emit("discover", p);
    await expect(bridge.connect(p.address, () => {})).rejects.toThrow("no answer within 0.02 s");
    expect(cancelled).toBe(1);
  });
});
