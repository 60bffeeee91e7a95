/**
 * The simulation stage (app/engine/pipeline/simulate.ts) with the real blocks: every substitution
 * of its table loads, and a simulated source has the device's output shape and rate.
 */
import { beforeAll, describe, expect, test } from "vitest";
import {
  createCatalog,
  formatDiagnostic,
  loadPipeline,
  Runtime,
  VirtualClock,
  type Diagnostic,
  type PlanBlock,
} from "../../engine";
import {
  simulateDevices,
  SIMULATED_DEVICES,
  withSimulatedDevices,
  type SimulateOptions,
} from "../../engine/pipeline/simulate";
import { runVirtual } from "../../engine/runtime/virtual";
import { noResources } from "../../engine/testing";
import { initDspForTests } from "../../../tests/support/wasm";
import { BLOCKS } from "../catalog";

const catalog = createCatalog(BLOCKS);
beforeAll(() => initDspForTests());

/** Loads (optionally simulating) and plans a pipeline: its blocks by name, the diagnostics. */
async function plan(yaml: string, simulate?: SimulateOptions) {
  const loaded = withSimulatedDevices(loadPipeline(yaml, "p.yaml", catalog), catalog, simulate);
  if (!loaded.spec) throw new Error(loaded.diagnostics.map(formatDiagnostic).join("\n"));
  const clock = new VirtualClock(0);
  const created = await Runtime.create({
    spec: loaded.spec,
    catalog,
    clock,
    virtual: true,
    resources: noResources,
    ignorePlacement: true,
  });
  if (!created.runtime) throw new Error(created.diagnostics.map(formatDiagnostic).join("\n"));
  const blocks = new Map<string, PlanBlock>(created.plan!.blocks.map((b) => [b.name, b]));
  return {
    blocks,
    runtime: created.runtime,
    clock,
    infos: loaded.diagnostics.filter((d) => d.severity === "info"),
    spec: loaded.spec,
  };
}

/** The device's output as its consumer sees it: shape and rate. */
const seen = (blocks: Map<string, PlanBlock>, consumer: string, index = 0) => {
  const inp = blocks.get(consumer)!.inputs[index]!;
  const src = blocks.get(inp.block)!;
  return {
    shape: src.outputs.find((o) => o.name === inp.port)!.shape,
    rate: src.desiredRate,
  };
};

const messages = (ds: Diagnostic[]) => ds.map((d) => d.message);

const SOURCES: [string, string][] = [
  ["Myo", "{ Type: Myo, Inputs: [t], Params: [ '' ] }"],
  ["Muovi", "{ Type: Muovi, Inputs: [t], Params: [0, 1] }"],
  ["MuoviSingleProbe", "{ Type: MuoviSingleProbe, Inputs: [t], Params: [0] }"],
  ["Delsys", "{ Type: Delsys, Inputs: [t] }"],
  ["DLR_ADCBT", "{ Type: DLR_ADCBT, Inputs: [t], Params: [ COM3, 4 ] }"],
  ["NilsPod", "{ Type: NilsPod, Inputs: [t] }"],
  ["HannesReceiver", "{ Type: HannesReceiver, Inputs: [t], Params: [ 11000, 6 ] }"],
];

describe("simulated sources: the device's output shape and rate", () => {
  for (const [type, block] of SOURCES) {
    test(type, async () => {
      const yaml = `t: { Type: ScheduledTimer, DesiredRate: 100 }\ndev: ${block}\nuse: { Type: Sink, Inputs: [dev] }\n`;
      const real = await plan(yaml);
      const sim = await plan(yaml, {});
      expect(seen(sim.blocks, "use")).toEqual(seen(real.blocks, "use"));
      expect(sim.infos).toHaveLength(1);
      expect(sim.infos[0]).toMatchObject({
        block: "dev",
        line: 2,
        col: 1,
        code: "simulated-device",
      });
      expect(sim.infos[0]!.message).toMatch(new RegExp(`^block 'dev' \\(${type}\\) simulated by `));
      // It runs: one event per tick (MuoviSingleProbe: one window of 20 samples per 20 ticks of 2 kHz).
      sim.runtime.start();
      runVirtual(sim.runtime, sim.clock, 1);
      const tel = sim.runtime.telemetry().blocks.find((b) => b.name === "use")!;
      expect(tel.errors).toBe(0);
      expect(Math.abs(tel.events - 100)).toBeLessThanOrEqual(1);
      sim.runtime.dispose();
      real.runtime.dispose();
    });
  }

  test("MuoviSingleProbe below 2 kHz: EMG at 2 kHz framed into the original's matrices", async () => {
    const sim = await plan(
      "t: { Type: ScheduledTimer, DesiredRate: 100 }\np: { Type: MuoviSingleProbe, Inputs: [t] }\nuse: { Type: Sink, Inputs: [p] }\n",
      {},
    );
    expect([...sim.blocks.values()].map((b) => `${b.name}:${b.type}`)).toEqual([
      "t:ScheduledTimer",
      "p_clock:ScheduledTimer",
      "p_emg:EmgSimulator",
      "p:SlidingWindow",
      "use:Sink",
    ]);
    expect(seen(sim.blocks, "use")).toEqual({ shape: { rows: 20, cols: 32 }, rate: 100 });
    sim.runtime.dispose();
  });

  test("a Myo without a timer gets one at 200 Hz; its imu output an ImuSimulator at 50 Hz", async () => {
    const yaml =
      "arm_clock: { Type: ScheduledTimer, DesiredRate: 10 }\n" +
      "arm: { Type: Myo }\n" +
      "emg: { Type: Sink, Inputs: [arm] }\n" +
      "imu: { Type: Sink, Inputs: [arm.imu] }\n";
    const real = await plan(yaml);
    const sim = await plan(yaml, {});
    expect(seen(sim.blocks, "emg")).toEqual(seen(real.blocks, "emg"));
    expect(seen(sim.blocks, "imu")).toEqual({ ...seen(real.blocks, "imu"), rate: 50 });
    expect(sim.blocks.get("arm_clock2")).toMatchObject({
      type: "ScheduledTimer",
      desiredRate: 200,
    });
    expect(sim.blocks.get("imu")!.inputs).toEqual([{ block: "arm_imu", port: "imu" }]);
    expect(messages(sim.infos)).toEqual([
      "block 'arm' (Myo) simulated by EmgSimulator, 8 channels at 200 Hz (a new ScheduledTimer); gesture keys in the app; its imu output: ImuSimulator arm_imu at 50 Hz",
    ]);
    sim.runtime.dispose();
    real.runtime.dispose();
  });
});

describe("output devices: a SimulatedOutput that counts", () => {
  test("BlenderArm, UdpSender (one datagram per value after a ControlAlgorithm), ROS, HannesGUI, HannesHand, a writing SerialPort", async () => {
    const yaml = `
t: { Type: ScheduledTimer, DesiredRate: 25 }
pred: { Type: SinGenerator, Inputs: [t], Params: [12] }
ctrl: { Type: ControlAlgorithm, Inputs: [pred], Params: [ algorithm:DirectControl ] }
arm: { Type: BlenderArm, Inputs: [ctrl], Params: [ localhost, 3334 ] }
udp: { Type: UDP_StreamlinedSender, Inputs: [ctrl, pred], Params: [ localhost, 11000 ] }
ros: { Type: ROS, Inputs: [pred], Params: [ localhost, publish, out, std_msgs/Float64MultiArray, 12 ] }
gui: { Type: HannesGUI, Inputs: [ctrl], Params: { Port: 8889 } }
hand: { Type: HannesHand, Inputs: [ctrl] }
serial: { Type: SerialPort, Inputs: [pred], Params: { Path: /dev/ttyUSB0, Channels: 12 } }
`;
    const sim = await plan(yaml, {});
    for (const name of ["arm", "udp", "ros", "gui", "hand", "serial"]) {
      expect(sim.blocks.get(name)!.type, name).toBe("SimulatedOutput");
    }
    expect(messages(sim.infos)).toEqual([
      "block 'arm' (BlenderArm) replaced by SimulatedOutput, counting the datagrams it would have sent to localhost:3334",
      "block 'udp' (UdpSender) replaced by SimulatedOutput, counting the datagrams it would have sent to localhost:11000",
      "block 'ros' (ROS) replaced by SimulatedOutput, counting the messages it would have sent to ws://localhost:9090 /out",
      "block 'gui' (HannesGUI) replaced by SimulatedOutput, counting the datagrams it would have sent to 127.0.0.1:8889",
      "block 'hand' (HannesHand) replaced by SimulatedOutput, counting the commands it would have sent to COM50",
      "block 'serial' (SerialPort) replaced by SimulatedOutput, counting the frames it would have sent to /dev/ttyUSB0",
    ]);
    sim.runtime.start();
    runVirtual(sim.runtime, sim.clock, 1);
    const text = (n: string) => sim.runtime.telemetry().blocks.find((b) => b.name === n)!.text;
    sim.runtime.stop();
    // 26 ticks (0 … 1 s); the sender: 11 control datagrams (one per value) + 1 for the vector.
    expect(text("arm")).toBe("simulated BlenderArm → localhost:3334: 26 datagrams not sent");
    expect(text("udp")).toBe("simulated UdpSender → localhost:11000: 312 datagrams not sent");
    sim.runtime.dispose();
  });

  test("kept: a sender whose receiver is in the pipeline, a HannesHand whose reference is used, a SerialPort that is read", async () => {
    const sim = await plan(
      `
t: { Type: ScheduledTimer, DesiredRate: 25 }
pred: { Type: SinGenerator, Inputs: [t], Params: [12] }
tx: { Type: UdpSender, Inputs: [pred], Params: { Port: 47001 } }
rx: { Type: UdpReceiver, Params: { Port: 47001, Channels: 12 } }
hand: { Type: HannesHand, Inputs: [pred] }
ref: { Type: Sink, Inputs: [hand.reference] }
serial: { Type: SerialPort, Params: { Path: /dev/ttyUSB0, Channels: 2 } }
read: { Type: Sink, Inputs: [serial] }
`,
      {},
    );
    expect(["tx", "hand", "serial"].map((n) => sim.blocks.get(n)!.type)).toEqual([
      "UdpSender",
      "HannesHand",
      "SerialPort",
    ]);
    expect(messages(sim.infos)).toEqual([
      "block 'tx' (UdpSender) is not simulated: its datagrams go to rx, a UdpReceiver of this pipeline",
      "block 'hand' (HannesHand) is not simulated: its reference output is used by other blocks, which a SimulatedOutput does not have",
      "block 'serial' (SerialPort) is not simulated: what a serial device sends (its data and rate) cannot be simulated in general; without the port the block says so and the rest of the pipeline runs",
    ]);
    sim.runtime.dispose();
  });

  test("keepNetwork keeps UDP and ROS blocks and simulates hardware", async () => {
    const ok = await plan(
      `
t: { Type: ScheduledTimer, DesiredRate: 100 }
arm: { Type: Myo, Inputs: [t] }
udp: { Type: UdpSender, Inputs: [arm], Params: { Port: 3334 } }
ros: { Type: ROS, Params: { Topic: /in, Direction: subscribe, Channels: 2 } }
`,
      { keepNetwork: true },
    );
    expect(["arm", "udp", "ros"].map((n) => ok.blocks.get(n)!.type)).toEqual([
      "EmgSimulator",
      "UdpSender",
      "ROS",
    ]);
    ok.runtime.dispose();
  });
});

describe("ROS subscribers", () => {
  test("a topic this pipeline publishes loops back; another gets a SinGenerator at 50 Hz", async () => {
    const sim = await plan(
      `
t: { Type: ScheduledTimer, DesiredRate: 18 }
sig: { Type: SinGenerator, Inputs: [t], Params: [10] }
pub: { Type: ROS, Inputs: [sig], Params: [ localhost, publish, topic1, std_msgs/Float64MultiArray, 10 ] }
sub: { Type: ROS, Inputs: [], Params: [ localhost, subscribe, topic1, std_msgs/Float64MultiArray, 10 ] }
other: { Type: ROS, Inputs: [], Params: [ localhost, subscribe, topic3, std_msgs/Float64MultiArray, 10 ] }
a: { Type: Sink, Inputs: [sub] }
b: { Type: Sink, Inputs: [other] }
`,
      {},
    );
    expect(sim.blocks.get("sub")).toMatchObject({
      type: "Function",
      inputs: [{ block: "sig", port: "out" }],
    });
    expect(seen(sim.blocks, "a")).toEqual({ shape: { rows: 1, cols: 10 }, rate: 18 });
    expect(seen(sim.blocks, "b")).toEqual({ shape: { rows: 1, cols: 10 }, rate: 50 });
    sim.runtime.dispose();
  });
});

describe("the stage itself", () => {
  test("the loaded spec is not changed; non-device blocks are the same objects' copies", () => {
    const loaded = loadPipeline(
      "t: { Type: ScheduledTimer, DesiredRate: 100 }\narm: { Type: Myo, Inputs: [t] }\nf: { Type: Function, Inputs: [arm], Params: [ abs:0 ] }\n",
      "p.yaml",
      catalog,
    );
    const before = JSON.stringify(loaded.spec!.blocks.map((b) => [b.name, b.type, b.inputs]));
    const s = simulateDevices(loaded.spec!, catalog);
    expect(JSON.stringify(loaded.spec!.blocks.map((b) => [b.name, b.type, b.inputs]))).toBe(before);
    expect(s.substituted).toEqual(["arm"]);
    expect(s.spec.byName.get("arm")!.type).toBe("EmgSimulator");
    expect(s.spec.byName.get("f")!.inputs[0]).toMatchObject({ block: "arm", port: "emg" });
  });

  test("every rule names a block of the catalog and says what it becomes", () => {
    for (const [type, rule] of Object.entries(SIMULATED_DEVICES)) {
      expect(catalog.get(type)?.type, type).toBe(type);
      expect(rule.becomes).not.toBe("");
    }
  });
});
