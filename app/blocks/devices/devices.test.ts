import { describe, expect, test } from "vitest";
import {
  createCatalog,
  EMPTY_SHAPE,
  Frame,
  loadPipeline,
  matrixShape,
  vectorShape,
  type BlockContext,
} from "../../engine";
import { BlockHarness } from "../../engine/testing";
import { BLOCKS } from "../catalog";
import { Delsys } from "./delsys";
import { DLR_ADCBT } from "./dlr-adcbt";
import { ImuSimulator } from "./imu-simulator";
import { Muovi } from "./muovi";
import { MuoviSingleProbe } from "./muovi-single-probe";
import { NilsPod } from "./nilspod";
import { pacedDevice, type DeviceSampleSink } from "./paced-device";
import { SimulatedOutput } from "./simulated-output";

const catalog = createCatalog(BLOCKS);
const timer = (rate: number) => ({ shape: EMPTY_SHAPE, rate, isTimer: true });
const ticks = (times: number[]) =>
  Frame.from(
    EMPTY_SHAPE,
    times,
    times.map(() => []),
  );

/** The params a file's positional form gives, and the warnings. */
function load(block: string) {
  const r = loadPipeline(
    `t: { Type: ScheduledTimer, DesiredRate: 100 }\n${block}\n`,
    "f.yaml",
    catalog,
  );
  return {
    errors: r.diagnostics.filter((d) => d.severity === "error").map((d) => d.message),
    params: r.spec?.blocks[1]?.params,
  };
}

describe("the original's device types load with their positional forms", () => {
  test("Muovi [probes]: 32 channels per probe", () => {
    expect(load("m: { Type: Muovi, Inputs: [t], Params: [0, 1] }").params).toEqual({
      Probes: [0, 1],
      Host: "192.168.76.1",
      Port: 54320,
    });
    expect(load("m: { Type: Muovi, Inputs: [t], Params: [] }").errors[0]).toMatch(
      /expected the probe indices/,
    );
    expect(load("m: { Type: Muovi, Inputs: [t], Params: [1, 1] }").errors[0]).toMatch(
      /listed twice/,
    );
  });

  test("MuoviSingleProbe, Delsys, DLR_ADCBT, NilsPod", () => {
    expect(load("m: { Type: MuoviSingleProbe, Inputs: [t], Params: [2] }").params).toEqual({
      Probes: [2],
      Port: 54321,
    });
    expect(load("d: { Type: Delsys, Inputs: [t] }").params).toEqual({
      Sensors: 16,
      Host: "127.0.0.1",
      Aux: "none",
    });
    expect(load("a: { Type: DLR_ADCBT, Inputs: [t], Params: [ COM5, 8 ] }").params).toEqual({
      Port: "COM5",
      Channels: 8,
    });
    expect(load("a: { Type: DLR_ADCBT, Inputs: [t], Params: [ COM5 ] }").params).toEqual({
      Port: "COM5",
      Channels: 10,
    });
    expect(load("a: { Type: DLR_ADCBT, Inputs: [t] }").params).toEqual({ Channels: 10 });
    expect(
      load("n: { Type: NilsPod, Inputs: [t], Params: [ 'aa:bb:cc:dd:ee:ff' ] }").params,
    ).toEqual({ Address: "aa:bb:cc:dd:ee:ff" });
    expect(load("n: { Type: NilsPod, Inputs: [t], Params: [ '' ] }").params).toEqual({});
  });
});

describe("shapes and rates as the original's", () => {
  test("Muovi: one [1, 32 × probes] vector per tick", async () => {
    const h = await BlockHarness.create(Muovi, { Probes: [0, 2, 3] }, { inputs: [timer(100)] });
    expect(h.ports[0]!.shape).toEqual(vectorShape(96));
    h.push(ticks([1, 1.01]));
    expect(h.output("emg").t).toEqual([1, 1.01]);
  });

  test("MuoviSingleProbe: [2000 / rate, 32 × probes], a vector at 2 kHz", async () => {
    const m = await BlockHarness.create(MuoviSingleProbe, {}, { inputs: [timer(100)] });
    expect(m.ports[0]!.shape).toEqual(matrixShape(20, 32));
    const v = await BlockHarness.create(
      MuoviSingleProbe,
      { Probes: [0, 1] },
      { inputs: [timer(2000)] },
    );
    expect(v.ports[0]!.shape).toEqual(vectorShape(64));
    const d = await BlockHarness.create(MuoviSingleProbe, {}, { inputs: [timer(30)] });
    expect(d.ports[0]!.shape).toEqual(matrixShape(66, 32)); // the integer part, as the original
    await expect(
      BlockHarness.create(MuoviSingleProbe, {}, { inputs: [timer(4000)] }),
    ).rejects.toThrow(/faster than the probe samples/);
  });

  test("Delsys [1, Sensors], DLR_ADCBT [1, Channels], NilsPod [1, 6]", async () => {
    const d = await BlockHarness.create(Delsys, { Sensors: 4 }, { inputs: [timer(1926)] });
    expect(d.ports[0]!.shape).toEqual(vectorShape(4));
    const a = await BlockHarness.create(DLR_ADCBT, {}, { inputs: [timer(100)] });
    expect(a.ports[0]!.shape).toEqual(vectorShape(10));
    const n = await BlockHarness.create(NilsPod, {}, { inputs: [timer(100)] });
    expect(n.ports[0]!.shape).toEqual(vectorShape(6));
  });

  test("without a timer the error says what paces it", async () => {
    await expect(
      BlockHarness.create(NilsPod, {}, { inputs: [{ shape: vectorShape(2), rate: 50 }] }),
    ).rejects.toThrow(/paced by one timer input.*'in0' is not a timer/);
    await expect(BlockHarness.create(Delsys, {}, { inputs: [timer(0)] })).rejects.toThrow(
      /rate of timer 'in0' is unknown/,
    );
  });
});

describe("without the device", () => {
  test("starting says it is not reachable, what it tried and what to do; ticks give zeros", async () => {
    const h = await BlockHarness.create(Muovi, { Probes: [0] }, { inputs: [timer(100)] });
    h.start();
    expect(h.warnings).toHaveLength(1);
    // Muovi speaks its protocol over TCP, which this harness (as the browser build) lacks.
    expect(h.warnings[0]).toMatch(/the SyncStation at 192\.168\.76\.1:54320 cannot be reached/);
    expect(h.warnings[0]).toMatch(/--simulate-devices/);
    expect(h.text).toBe("TCP not available in the browser build; use --simulate-devices");
    h.push(ticks([0, 0.01, 0.02]));
    expect(
      h
        .output("emg")
        .v.flat()
        .every((x) => x === 0),
    ).toBe(true);
    expect(h.output("emg").t).toEqual([0, 0.01, 0.02]);
  });

  test("each device names its link", async () => {
    const texts: string[] = [];
    for (const [def, params] of [
      [Delsys, {}],
      [DLR_ADCBT, { Port: "COM7" }],
      [NilsPod, { Address: "aa:bb:cc:dd:ee:ff" }],
      [MuoviSingleProbe, {}],
    ] as const) {
      const h = await BlockHarness.create(def, params, { inputs: [timer(100)] });
      h.start();
      texts.push(h.warnings[0]!);
    }
    expect(texts[0]).toMatch(/Trigno Control Utility at 127\.0\.0\.1:50040/);
    expect(texts[1]).toMatch(/DLR ADC\/BT on serial port COM7 at 115200 Bd/);
    expect(texts[2]).toMatch(/NilsPod aa:bb:cc:dd:ee:ff over Bluetooth LE/);
    expect(texts[3]).toMatch(/TCP port 54321/);
  });
});

describe("pacedDevice with a protocol module", () => {
  /** A device block whose protocol hands its sink to the test. */
  async function withProtocol(maxQueue = 3) {
    let sink: DeviceSampleSink | undefined;
    let closed = 0;
    const h = await BlockHarness.create(
      {
        ...NilsPod,
        create: (ctx: BlockContext) =>
          pacedDevice(ctx, {
            device: "Test",
            target: "a test link",
            shape: vectorShape(2),
            port: "imu",
            maxQueue,
            protocol: {
              open(_ctx, s) {
                sink = s;
                return { close: () => void closed++ };
              },
            },
          }),
      },
      {},
      { inputs: [timer(100)] },
    );
    h.start();
    return { h, sink: () => sink!, closed: () => closed };
  }

  test("each tick emits the oldest waiting sample, repeats the last, drops the oldest when full", async () => {
    const { h, sink, closed } = await withProtocol(3);
    expect(h.text).toBe("connecting to a test link…");
    h.push(ticks([0]));
    sink().state("streaming", "streaming");
    for (const k of [1, 2, 3, 4]) sink().push([k, -k]);
    h.push(ticks([0.01, 0.02, 0.03, 0.04]));
    expect(h.output("imu").v).toEqual([
      [0, 0],
      [2, -2],
      [3, -3],
      [4, -4],
      [4, -4],
    ]);
    h.instance.stop?.();
    expect(closed()).toBe(1);
    expect(h.text).toMatch(/stopped · 4 samples · 1 dropped \(queue of 3\)/);
  });

  test("a lost link sends zeros again", async () => {
    const { h, sink } = await withProtocol();
    sink().state("streaming", "streaming");
    sink().push([5, 6]);
    h.push(ticks([0]));
    sink().state("lost", "link lost");
    h.push(ticks([0.01]));
    expect(h.output("imu").v).toEqual([
      [5, 6],
      [0, 0],
    ]);
    expect(h.text).toMatch(/^link lost/);
  });
});

describe("ImuSimulator", () => {
  test("acc-gyro: gravity turning with the roll, the roll rate on x (deg/s)", async () => {
    const h = await BlockHarness.create(ImuSimulator, { NoiseStd: 0 }, { inputs: [timer(100)] });
    expect(h.ports[0]!.shape).toEqual(vectorShape(6));
    h.push(ticks([0, 1, 2]));
    for (const v of h.output("imu").v) {
      expect(Math.hypot(v[0]!, v[1]!, v[2]!)).toBeCloseTo(9.80665, 9);
    }
    // θ = 60° · sin(2π t / 4): at t = 0 the rate is 60 · 2π/4 deg/s, at t = 1 the roll is 60°.
    expect(h.output("imu").v[0]![3]).toBeCloseTo(60 * ((2 * Math.PI) / 4), 9);
    expect(h.output("imu").v[1]![1]).toBeCloseTo(9.80665 * Math.sin(Math.PI / 3), 9);
  });

  test("myo: a unit quaternion, acceleration in g, [1, 10]", async () => {
    const h = await BlockHarness.create(ImuSimulator, { Layout: "myo" }, { inputs: [timer(50)] });
    expect(h.ports[0]!.shape).toEqual(vectorShape(10));
    h.push(ticks([0.3]));
    const v = h.output("imu").v[0]!;
    expect(Math.hypot(v[0]!, v[1]!, v[2]!, v[3]!)).toBeCloseTo(1, 12);
    expect(Math.hypot(v[4]!, v[5]!, v[6]!)).toBeCloseTo(1, 1);
  });
});

describe("SimulatedOutput", () => {
  test("counts what the device would have sent, per event or per value", async () => {
    const h = await BlockHarness.create(
      SimulatedOutput,
      {
        Device: "UdpSender",
        Destination: "localhost:11000",
        Unit: "datagram",
        Count: ["values", "events"],
      },
      { inputs: [{ shape: vectorShape(11) }, { shape: vectorShape(3) }] },
    );
    expect(h.text).toBe("simulated UdpSender → localhost:11000: 0 datagrams not sent");
    h.push(Frame.from(vectorShape(11), [1, 2], [new Array(11).fill(0), new Array(11).fill(1)]), 0);
    h.push(Frame.from(vectorShape(3), [3], [[1, 2, 3]]), 1);
    h.instance.stop?.();
    expect(h.text).toBe("simulated UdpSender → localhost:11000: 23 datagrams not sent");
    h.instance.reset?.();
    expect(h.text).toMatch(/: 0 datagrams not sent$/);
  });
});
