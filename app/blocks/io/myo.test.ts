import { describe, expect, test } from "vitest";
import {
  createCatalog,
  EMPTY_SHAPE,
  Frame,
  loadPipeline,
  type BleAdapterState,
  type BleBridge,
  type BlePeripheral,
} from "../../engine";
import { BlockHarness } from "../../engine/testing";
import { Myo } from "./myo";
import { MYO } from "./myo-protocol";
import { serializerFor } from "./udp-sender";
import { BLOCKS } from "../catalog";

const hex = (b: Uint8Array): string => Buffer.from(b).toString("hex");
const settle = (): Promise<void> => new Promise((r) => setTimeout(r, 0));

/** A Bluetooth adapter the test drives: armbands in range, links that drop, writes recorded. */
function fakeBle(adapter: BleAdapterState = "poweredOn", message?: string) {
  const dev = {
    state: (_s: BleAdapterState, _m?: string) => {},
    scans: [] as {
      services: readonly string[];
      found: (p: BlePeripheral) => void;
      stopped: boolean;
    }[],
    connects: [] as string[],
    failNext: "",
    writes: [] as string[],
    subscribed: [] as string[],
    notify: new Map<string, (d: Uint8Array) => void>(),
    lose: new Map<string, (reason: string) => void>(),
    disconnected: [] as string[],
    discovered: [MYO.commandCharacteristic, MYO.imuCharacteristic, ...MYO.emgCharacteristics],
  };
  const serviceOf = (u: string): string =>
    u === MYO.commandCharacteristic
      ? MYO.controlService
      : u === MYO.imuCharacteristic
        ? MYO.imuService
        : MYO.emgService;
  const bridge: BleBridge = {
    watchState(fn) {
      dev.state = fn;
      fn(adapter, message);
      return { close: () => (dev.state = () => {}) };
    },
    scan(o) {
      const s = { services: o.services, found: o.onFound, stopped: false };
      dev.scans.push(s);
      return { stop: () => (s.stopped = true) };
    },
    async connect(address, onDisconnect) {
      dev.connects.push(address);
      if (dev.failNext !== "") {
        const m = dev.failNext;
        dev.failNext = "";
        throw new Error(m);
      }
      dev.lose.set(address, onDisconnect);
      return {
        address,
        discover: async () =>
          dev.discovered.map((uuid) => ({ service: serviceOf(uuid), uuid, properties: [] })),
        subscribe: async (service, uuid, onData) => {
          dev.subscribed.push(
            `${address} ${service === MYO.emgService ? "emg" : "imu"} ${uuid.slice(4, 8)}`,
          );
          dev.notify.set(`${address} ${uuid}`, onData);
        },
        write: async (_s, _c, data) => {
          dev.writes.push(`${address} ${hex(data)}`);
        },
        disconnect: () => dev.disconnected.push(address),
      };
    },
  };
  /** The scan running now (the latest one not stopped). */
  const scan = () => dev.scans.filter((s) => !s.stopped).at(-1)!;
  const myo = (address: string): BlePeripheral => ({
    address,
    name: "Myo",
    services: [MYO.controlService],
  });
  return { bridge, dev, scan, myo };
}

const EMG = Uint8Array.of(
  0x00,
  0x01,
  0x7f,
  0x80,
  0xff,
  0x40,
  0xc0,
  0x02, // sample 1
  0x0a,
  0xf6,
  0x64,
  0x9c,
  0x00,
  0x00,
  0x03,
  0xfd, // sample 2
);
const SAMPLE1 = [0, 1, 127, -128, -1, 64, -64, 2];
const SAMPLE2 = [10, -10, 100, -100, 0, 0, 3, -3];
// w 1, x −0.5, y 0, z 0; accel 1, −0.5, 2 g; gyro 1, −2048, 16.125 deg/s
const IMU = Uint8Array.of(
  0x00,
  0x40,
  0x00,
  0xe0,
  0x00,
  0x00,
  0x00,
  0x00,
  0x00,
  0x08,
  0x00,
  0xfc,
  0x00,
  0x10,
  0x10,
  0x00,
  0x00,
  0x80,
  0x02,
  0x01,
);

const A = "aa:bb:cc:dd:ee:ff";
const B = "11:22:33:44:55:66";

describe("Myo", () => {
  test("scan, connect, commands written, notifications become emg and imu events", async () => {
    const { bridge, dev, scan, myo } = fakeBle();
    const h = await BlockHarness.create(
      Myo,
      { Address: "AA:BB:CC:DD:EE:FF" },
      { io: { ble: bridge } },
    );
    expect(h.ports.map((p) => p.name)).toEqual(["emg", "imu"]);
    expect(h.desiredRate).toBe(200);
    h.start();
    expect(scan().services).toEqual([MYO.controlService]);
    expect(h.text).toBe("searching for AA:BB:CC:DD:EE:FF…");
    // Another armband is not the one asked for.
    scan().found(myo(B));
    expect(dev.connects).toEqual([]);
    scan().found(myo(A));
    expect(dev.scans[0]!.stopped).toBe(true);
    expect(dev.connects).toEqual([A]);
    expect(h.text).toBe(`connecting to ${A}…`);
    await settle();
    expect(dev.writes).toEqual([
      `${A} 090101`, // never sleep
      `${A} 0103020100`, // EMG filtered, IMU data, classifier off
      `${A} 030101`, // vibrate short
    ]);
    expect(dev.subscribed).toEqual([
      `${A} emg 0105`,
      `${A} emg 0205`,
      `${A} emg 0305`,
      `${A} emg 0405`,
      `${A} imu 0402`,
    ]);
    expect(h.text).toBe(`${A} streaming · 0 EMG samples · 0 IMU`);

    h.clock = 100;
    dev.notify.get(`${A} ${MYO.emgCharacteristics[0]}`)!(EMG);
    h.clock = 100.012;
    dev.notify.get(`${A} ${MYO.emgCharacteristics[1]}`)!(EMG);
    const emg = h.output("emg");
    expect(emg.frames).toEqual([2, 2]);
    expect(emg.t[0]).toBeCloseTo(99.995, 9);
    expect(emg.t[1]).toBe(100);
    expect(emg.t[2]).toBeCloseTo(100.005, 9);
    expect(emg.t[3]).toBeCloseTo(100.01, 9);
    expect(emg.v[0]).toEqual(SAMPLE1.map((x) => x / 128));
    expect(emg.v[1]).toEqual(SAMPLE2.map((x) => x / 128));

    h.clock = 100.02;
    dev.notify.get(`${A} ${MYO.imuCharacteristic}`)!(IMU);
    expect(h.output("imu").t).toEqual([100.02]);
    expect(h.output("imu").v).toEqual([[1, -0.5, 0, 0, 1, -0.5, 2, 1, -2048, 16.125]]);

    // A malformed notification is counted, not thrown.
    dev.notify.get(`${A} ${MYO.emgCharacteristics[2]}`)!(new Uint8Array(3));
    expect(h.text).toBe(
      `${A} streaming · 4 EMG samples · 1 IMU · 1 malformed (last: 3 bytes, an EMG notification has 16)`,
    );

    // stop: MOSAIC's end commands (EMG/IMU off, normal sleep), then disconnect.
    h.instance.stop?.();
    await settle();
    expect(dev.writes.slice(3)).toEqual([`${A} 0103000000`, `${A} 090100`]);
    expect(dev.disconnected).toEqual([A]);
    expect(h.text).toMatch(/^aa:bb:cc:dd:ee:ff disconnected/);
    h.instance.dispose?.();
    h.instance.dispose?.();
  });

  test("the emg output follows MOSAIC's convention: UdpSender's auto serializer sends the bytes back", async () => {
    expect(serializerFor(Myo.type)).toBe("myo");
    const { bridge, dev, scan, myo } = fakeBle();
    const h = await BlockHarness.create(
      Myo,
      { EMG: "raw", IMU: false, Vibrate: false },
      {
        io: { ble: bridge },
      },
    );
    h.start();
    scan().found(myo(A));
    await settle();
    // Raw EMG, IMU off, no vibration; the IMU characteristic is not subscribed.
    expect(dev.writes).toEqual([`${A} 090101`, `${A} 0103030000`]);
    expect(dev.subscribed.some((s) => s.includes("imu"))).toBe(false);
    expect(h.text).toBe(`${A} streaming · 0 EMG samples`);
    dev.notify.get(`${A} ${MYO.emgCharacteristics[3]}`)!(EMG);
    // value · 128 is the int8 the armband sent: what the myo serializer writes.
    expect(h.output("emg").v.map((v) => v.map((x) => x * 128))).toEqual([SAMPLE1, SAMPLE2]);
  });

  test("a lost link is reported and the armband searched for again; a failed connection too", async () => {
    const { bridge, dev, scan, myo } = fakeBle();
    const h = await BlockHarness.create(Myo, { Reconnect: 2 }, { io: { ble: bridge } });
    h.start();
    expect(h.text).toBe("searching for a Myo armband…");
    h.clock = 5;
    scan().found(myo(A));
    await settle();
    expect(h.text).toMatch(/streaming/);
    dev.lose.get(A)!("out of range");
    expect(h.text).toBe(
      `${A}: disconnected (out of range); searching again in 2 s · 1 disconnection`,
    );
    expect(h.warnings).toEqual([`${A}: disconnected (out of range)`]);
    // Notifications of the old link no longer count.
    dev.notify.get(`${A} ${MYO.emgCharacteristics[0]}`)!(EMG);
    expect(h.output("emg").t).toEqual([]);
    expect(h.oneShot?.t).toBe(7);
    expect(dev.scans.filter((s) => !s.stopped)).toHaveLength(0);
    h.fireOneShot();
    expect(h.text).toBe("searching for a Myo armband… · 1 disconnection");
    dev.failNext = "no answer within 10 s";
    scan().found(myo(A));
    await settle();
    expect(h.text).toBe(
      `${A}: connection failed: no answer within 10 s; searching again in 2 s · 1 disconnection`,
    );
    h.fireOneShot();
    scan().found(myo(A));
    await settle();
    expect(dev.connects).toEqual([A, A, A]);
    expect(h.text).toBe(`${A} streaming · 0 EMG samples · 0 IMU · 1 disconnection`);
    h.clock = 10;
    dev.notify.get(`${A} ${MYO.emgCharacteristics[0]}`)!(EMG);
    expect(h.output("emg").t).toEqual([9.995, 10]);
    h.instance.dispose?.();
  });

  test("no bridge, no adapter, adapter off: the status says so; an armband without EMG is refused", async () => {
    const none = await BlockHarness.create(Myo, {}, {});
    none.start();
    expect(none.text).toMatch(/^Bluetooth LE is not available here \(browser build\)/);
    none.instance.stop?.();
    none.instance.dispose?.();

    const missing = fakeBle("unavailable", "no Bluetooth adapter (EAFNOSUPPORT)");
    const h = await BlockHarness.create(Myo, {}, { io: { ble: missing.bridge } });
    h.start();
    expect(h.text).toBe("no Bluetooth adapter (EAFNOSUPPORT)");
    expect(missing.dev.scans).toEqual([]);

    const off = fakeBle("poweredOff");
    const h2 = await BlockHarness.create(Myo, {}, { io: { ble: off.bridge } });
    h2.start();
    expect(h2.text).toMatch(/^Bluetooth is off/);
    // Switched on: the search starts.
    off.dev.state("poweredOn");
    expect(h2.text).toBe("searching for a Myo armband…");
    // Something that advertises the Myo service but has no EMG characteristics.
    off.dev.discovered = [MYO.commandCharacteristic];
    off.scan().found(off.myo(B));
    await settle();
    expect(h2.text).toMatch(
      /^11:22:33:44:55:66: not a Myo armband \(missing characteristic d5060105/,
    );
    expect(off.dev.disconnected).toEqual([B]);
    // The adapter switched off while searching again.
    h2.fireOneShot();
    off.dev.state("poweredOff");
    expect(off.dev.scans.every((s) => s.stopped)).toBe(true);
    expect(h2.text).toMatch(/^Bluetooth is off/);
  });

  test("several armbands: blocks without Address take different ones", async () => {
    const { bridge, dev, myo } = fakeBle();
    const one = await BlockHarness.create(Myo, {}, { io: { ble: bridge } });
    const two = await BlockHarness.create(Myo, {}, { io: { ble: bridge } });
    one.start();
    two.start();
    dev.scans[0]!.found(myo(A));
    dev.scans[1]!.found(myo(A)); // taken by the first block
    dev.scans[1]!.found(myo(B));
    await settle();
    expect(dev.connects).toEqual([A, B]);
    dev.notify.get(`${B} ${MYO.emgCharacteristics[0]}`)!(EMG);
    expect(one.output("emg").t).toHaveLength(0);
    expect(two.output("emg").t).toHaveLength(2);
    one.instance.dispose?.();
    two.instance.dispose?.();
  });

  test("with a timer input (MOSAIC's form): one sample per tick, zeros until streaming, MaxDelay", async () => {
    const { bridge, dev, scan, myo } = fakeBle();
    const h = await BlockHarness.create(
      Myo,
      { MaxDelay: 3 },
      {
        io: { ble: bridge },
        inputs: [{ shape: EMPTY_SHAPE, rate: 200, isTimer: true }],
      },
    );
    const tick = (t: number) => h.push(Frame.from(EMPTY_SHAPE, [t], [[]]));
    h.start();
    tick(1);
    expect(h.output("emg").v).toEqual([[0, 0, 0, 0, 0, 0, 0, 0]]);
    scan().found(myo(A));
    await settle();
    dev.notify.get(`${A} ${MYO.emgCharacteristics[0]}`)!(EMG);
    h.clock = 1.5; // the status text is refreshed at most every 0.5 s with the data
    dev.notify.get(`${A} ${MYO.emgCharacteristics[1]}`)!(EMG.map((b) => (b + 1) & 0xff));
    // Four samples arrived, three are kept: the oldest was dropped.
    expect(h.text).toMatch(/1 EMG samples dropped \(MaxDelay\)/);
    h.clear();
    h.push(Frame.from(EMPTY_SHAPE, [2, 2.005, 2.01, 2.015], [[], [], [], []]));
    const s = (v: number[]) => v.map((x) => x / 128);
    const inc = (v: number[]) => v.map((x) => (x === 127 ? -128 : x + 1)); // int8 wraps
    expect(h.output("emg").t).toEqual([2, 2.005, 2.01, 2.015]);
    expect(h.output("emg").v).toEqual([
      s(SAMPLE2),
      s(inc(SAMPLE1)),
      s(inc(SAMPLE2)),
      s(inc(SAMPLE2)), // none waiting: the last one again
    ]);
    expect(() =>
      BlockHarness.create(Myo, {}, { inputs: [{ shape: EMPTY_SHAPE, rate: 10, isTimer: false }] }),
    ).rejects.toThrow(/not a timer/);
  });

  test("MOSAIC's positional form: Type MYO, a timer input, the address in Params", () => {
    expect(Myo.legacyParams!(["00:11:22:33:44:55"])).toEqual({ Address: "00:11:22:33:44:55" });
    expect(Myo.legacyParams!([])).toEqual({});
    const r = loadPipeline(
      'T: { Type: ScheduledTimer, DesiredRate: 200 }\nM: { Type: MYO, Inputs: [T], Params: ["00:11:22:33:44:55"] }\n',
      "legacy.yaml",
      createCatalog(BLOCKS),
    );
    expect(r.spec?.blocks.find((b) => b.name === "M")?.params).toMatchObject({
      Address: "00:11:22:33:44:55",
    });
  });
});
