/**
 * Simulated devices (`mosaic run --simulate-devices`, the app's Simulate devices switch, the
 * browser build by default): a stage after loading that rewrites a valid `PipelineSpec` so that it
 * runs without hardware. Every block that reads a device becomes a simulator with the same output
 * shape and rate (EmgSimulator for EMG, so the app's gesture keys drive it; ImuSimulator for an
 * IMU; SinGenerator for other signals), and every block that sends to a device or over the network
 * becomes a `SimulatedOutput` that counts what it would have sent. The substitutions are the one
 * table `SIMULATED_DEVICES`; each one applied is reported as ONE info line (a diagnostic of
 * severity info, at the block). Nothing else of the pipeline changes: the other blocks keep their
 * names, params and wiring, and the block that takes a device's place keeps its name (and its
 * `Path`), so every input that named the device still does. docs/mosaic-compatibility.md lists
 * the table.
 */
import { outputNames, type AnyBlockDefinition } from "../block";
import type { Catalog } from "../catalog";
import type { Diagnostic } from "../diagnostics";
import type { BlockSpec, InputRef, LoadResult, PipelineSpec } from "./spec";

export interface SimulateOptions {
  /**
   * Keep the blocks that talk over the network (UDP and ROS: BlenderArm, HannesGUI, UdpSender,
   * ROS): only hardware is simulated, so a local receiver (Blender, a decoder, a rosbridge) gets
   * what the pipeline sends.
   */
  keepNetwork?: boolean;
}

/** One block of a substitution. */
interface NewBlock {
  name: string;
  type: string;
  params: Record<string, unknown>;
  /** Inputs: block names (their default port), or the device's own inputs (copied as written). */
  inputs: (string | InputRef)[];
  desiredRate?: number;
}

/** What takes a device block's place. */
export interface Replacement {
  /** The new blocks, sources first; the one named like the device carries its name and Path. */
  blocks: NewBlock[];
  /** Where each output port of the device now comes from (default: the block of its name). */
  ports?: Record<string, { block: string; port: string }>;
  /** What it became, for the info line: "EmgSimulator, 8 channels at 200 Hz (its timer's)". */
  summary: string;
}

/** What a rule may ask about the pipeline. */
export interface SimulationEnv {
  readonly spec: PipelineSpec;
  /** The rate (Hz) of a block as the file gives it (timers), undefined when unknown. */
  rateOf(block: string): number | undefined;
  /** A block name not used yet in the pipeline, from `base`. */
  freshName(base: string): string;
  /** True when some block reads the output port `port` of `block`. */
  consumed(block: string, port?: string): boolean;
  /** The pipeline's blocks of one type, in file order (indexed once: no scan per device). */
  ofType(type: string): readonly BlockSpec[];
  readonly keepNetwork: boolean;
}

export interface DeviceRule {
  /** A source (reads a device) or an output (sends to one). */
  kind: "source" | "output";
  /** Talks over the network (UDP, ROS): kept with `keepNetwork`. */
  network: boolean;
  /** What it becomes, in words (the docs' table). */
  becomes: string;
  /**
   * The replacement of one block of this type; a string when the block is left as it is, saying
   * why (reported as the info line).
   */
  substitute(b: BlockSpec, env: SimulationEnv): Replacement | string;
}

const LOOPBACK = /^(127\.\d+\.\d+\.\d+|localhost|::1|0\.0\.0\.0|::)$/i;

/** A seed from a block name, so that two simulated armbands differ and every run is the same. */
function seedOf(name: string): number {
  let h = 2166136261;
  for (let i = 0; i < name.length; i++) h = Math.imul(h ^ name.charCodeAt(i), 16777619);
  return h >>> 0;
}

const p = (b: BlockSpec): Record<string, unknown> => b.params as Record<string, unknown>;
const hz = (r: number | undefined): string =>
  r === undefined ? "its timer's rate" : `${Math.round(r * 1000) / 1000} Hz`;

/** The device's timer input (its first input), as written. */
const timerOf = (b: BlockSpec): InputRef | undefined => b.inputs[0];

/** An EmgSimulator on a new ScheduledTimer at `rate`, for an EMG device without a timer input. */
function emgAtRate(b: BlockSpec, env: SimulationEnv, channels: number, rate: number): Replacement {
  const clock = env.freshName(`${b.name}_clock`);
  return {
    blocks: [
      { name: clock, type: "ScheduledTimer", params: {}, inputs: [], desiredRate: rate },
      {
        name: b.name,
        type: "EmgSimulator",
        params: { Channels: channels, Seed: seedOf(b.name) },
        inputs: [clock],
      },
    ],
    ports: { [b.outputs[0]!]: { block: b.name, port: "emg" } },
    summary: `EmgSimulator, ${channels} channels at ${hz(rate)} (a new ScheduledTimer at the device's rate); gesture keys in the app`,
  };
}

/** An EmgSimulator in place of an EMG device paced by its timer input. */
function emgOnTimer(
  b: BlockSpec,
  env: SimulationEnv,
  channels: number,
  extra: Record<string, unknown> = {},
): Replacement {
  const timer = timerOf(b)!;
  return {
    blocks: [
      {
        name: b.name,
        type: "EmgSimulator",
        params: { Channels: channels, Seed: seedOf(b.name), ...extra },
        inputs: [timer],
      },
    ],
    ports: { [b.outputs[0]!]: { block: b.name, port: "emg" } },
    summary: `EmgSimulator, ${channels} channels at ${hz(env.rateOf(timer.block))} (its timer's; gesture keys in the app)`,
  };
}

/** A SimulatedOutput in place of a block that sends. */
function sink(
  b: BlockSpec,
  destination: string,
  unit: string,
  count: "events" | ("events" | "values")[] = "events",
): Replacement {
  return {
    blocks: [
      {
        name: b.name,
        type: "SimulatedOutput",
        params: { Device: b.type, Destination: destination, Unit: unit, Count: count },
        inputs: [...b.inputs],
      },
    ],
    summary: `SimulatedOutput, counting the ${unit}s it would have sent${destination ? ` to ${destination}` : ""}`,
  };
}

const endpoint = (host: unknown, port: unknown): string =>
  `${String(host).includes(":") ? `[${String(host)}]` : String(host)}:${String(port)}`;

/** The Trigno's native EMG rate: 26 samples per 13.5 ms frame (app/blocks/devices/delsys-protocol.ts). */
const TRIGNO_NATIVE_RATE = 26 / 0.0135;

/** Myo's EMG as the armband gives it: int8 / 128, filtered on board (no hum). */
const MYO_EMG = { AmplitudeMv: 0.25, NoiseFloorMv: 0.005, HumMv: 0 };

/** BrainFlow's own simulators: a block on one of them is left as it is. */
const BRAINFLOW_SIMULATORS = /^(synthetic(_board)?|playback(_file(_board)?)?|-1|-3)$/i;

/**
 * A BrainFlow block on BrainFlow's synthetic board in the board's own layout and rate
 * (`Simulated`: no device opened); its connection params are dropped.
 */
function brainflowSynthetic(b: BlockSpec): Replacement | string {
  const board = String(p(b).Board).trim();
  if (BRAINFLOW_SIMULATORS.test(board)) {
    return `left as it is: board ${board} is one of BrainFlow's own simulators`;
  }
  const keep = Object.fromEntries(
    ["Board", "Library", "Channels", "PollRate", "Silence", "Retry", "LogLevel"].flatMap((k) =>
      p(b)[k] !== undefined ? [[k, p(b)[k]]] : [],
    ),
  );
  return {
    blocks: [{ name: b.name, type: "BrainFlow", params: { ...keep, Simulated: true }, inputs: [] }],
    summary: `BrainFlow's synthetic board in ${board}'s channels and at its rate (Simulated: true)`,
  };
}

/**
 * The substitutions, by block type (the canonical `Type`). docs/mosaic-compatibility.md §7
 * mirrors this table.
 */
export const SIMULATED_DEVICES: Readonly<Record<string, DeviceRule>> = {
  Myo: {
    kind: "source",
    network: false,
    becomes:
      "EmgSimulator with 8 channels on its timer (a ScheduledTimer at 200 Hz when it has none); its imu output, when used, an ImuSimulator (Myo layout) at 50 Hz",
    substitute(b, env) {
      const blocks: NewBlock[] = [];
      let timer: string | InputRef | undefined = timerOf(b);
      let rate = timer ? env.rateOf(timer.block) : 200;
      if (!timer) {
        const clock = env.freshName(`${b.name}_clock`);
        blocks.push({
          name: clock,
          type: "ScheduledTimer",
          params: {},
          inputs: [],
          desiredRate: 200,
        });
        timer = clock;
        rate = 200;
      }
      blocks.push({
        name: b.name,
        type: "EmgSimulator",
        params: { Channels: 8, Seed: seedOf(b.name), ...MYO_EMG },
        inputs: [timer],
      });
      const ports: Record<string, { block: string; port: string }> = {
        emg: { block: b.name, port: "emg" },
      };
      let summary = `EmgSimulator, 8 channels at ${hz(rate)}${timerOf(b) ? " (its timer's)" : " (a new ScheduledTimer)"}; gesture keys in the app`;
      if (env.consumed(b.name, "imu")) {
        const clock = env.freshName(`${b.name}_imu_clock`);
        const imu = env.freshName(`${b.name}_imu`);
        blocks.unshift({
          name: clock,
          type: "ScheduledTimer",
          params: {},
          inputs: [],
          desiredRate: 50,
        });
        blocks.push({
          name: imu,
          type: "ImuSimulator",
          params: { Layout: "myo", Seed: seedOf(imu) },
          inputs: [clock],
        });
        ports.imu = { block: imu, port: "imu" };
        summary += `; its imu output: ImuSimulator ${imu} at 50 Hz`;
      }
      return { blocks, ports, summary };
    },
  },
  Muovi: {
    kind: "source",
    network: false,
    becomes:
      "EmgSimulator with 32 × probes channels on its timer (without one, a new ScheduledTimer at the probes' 2000 Hz)",
    substitute: (b, env) => {
      const channels = 32 * (p(b).Probes as number[]).length;
      return timerOf(b) ? emgOnTimer(b, env, channels) : emgAtRate(b, env, channels, 2000);
    },
  },
  MuoviSingleProbe: {
    kind: "source",
    network: false,
    becomes:
      "EmgSimulator with 32 × probes channels; below 2 kHz, at 2 kHz (a new ScheduledTimer) framed by a SlidingWindow into the same [2000 / rate, channels] matrices (without a timer, at 2 kHz)",
    substitute(b, env) {
      const channels = 32 * (p(b).Probes as number[]).length;
      const timer = timerOf(b);
      if (!timer) return emgAtRate(b, env, channels, 2000);
      const rate = env.rateOf(timer.block);
      const rows = rate !== undefined ? Math.floor(2000 / rate) : 1;
      if (rows <= 1) return emgOnTimer(b, env, channels);
      const clock = env.freshName(`${b.name}_clock`);
      const emg = env.freshName(`${b.name}_emg`);
      return {
        blocks: [
          { name: clock, type: "ScheduledTimer", params: {}, inputs: [], desiredRate: 2000 },
          {
            name: emg,
            type: "EmgSimulator",
            params: { Channels: channels, Seed: seedOf(b.name) },
            inputs: [clock],
          },
          {
            name: b.name,
            type: "SlidingWindow",
            params: { Length: rows, Step: rows },
            inputs: [emg],
          },
        ],
        ports: { emg: { block: b.name, port: "out" } },
        summary: `EmgSimulator ${emg} (${channels} channels at 2000 Hz) framed by a SlidingWindow into [${rows}, ${channels}] every ${rows} samples (${hz(2000 / rows)})`,
      };
    },
  },
  Quattrocento: {
    kind: "source",
    network: false,
    becomes:
      "EmgSimulator with its output channels (Select, or the listed Connectors' 16 or 64 each) on a new ScheduledTimer at its Rate",
    substitute: (b, env) => {
      const q = p(b);
      const select = q.Select as number[] | undefined;
      const connectors = q.Connectors as string[];
      const channels =
        select?.length ?? connectors.reduce((n, c) => n + (c.startsWith("MULTIPLE") ? 64 : 16), 0);
      return emgAtRate(b, env, channels, q.Rate as number);
    },
  },
  Sessantaquattro: {
    kind: "source",
    network: false,
    becomes:
      "EmgSimulator with its output channels (Channels, halved in bipolar Mode, plus 4 or 8 Extras) on a new ScheduledTimer at its Rate",
    substitute: (b, env) => {
      const q = p(b);
      const nch = (q.Channels as number | undefined) ?? 64;
      const bio = q.Mode === "bipolar" ? nch / 2 : nch;
      const extras = q.Extras === false ? 0 : q.Model === "Sessantaquattro" ? 4 : 8;
      return emgAtRate(b, env, bio + extras, (q.Rate as number | undefined) ?? 2000);
    },
  },
  Delsys: {
    kind: "source",
    network: false,
    becomes:
      "EmgSimulator with one channel per sensor (plus its AUX channels) on its timer (without one, a new ScheduledTimer at the Trigno's native 1925.926 Hz)",
    substitute(b, env) {
      const sensors = p(b).Sensors as number | number[];
      const aux = { none: 0, acc: 3, imu: 9 }[
        (p(b).Aux as "none" | "acc" | "imu" | undefined) ?? "none"
      ];
      const channels = (Array.isArray(sensors) ? sensors.length : sensors) * (1 + aux);
      if (timerOf(b)) return emgOnTimer(b, env, channels);
      const clock = env.freshName(`${b.name}_clock`);
      return {
        blocks: [
          {
            name: clock,
            type: "ScheduledTimer",
            params: {},
            inputs: [],
            desiredRate: TRIGNO_NATIVE_RATE,
          },
          {
            name: b.name,
            type: "EmgSimulator",
            params: { Channels: channels, Seed: seedOf(b.name) },
            inputs: [clock],
          },
        ],
        ports: { [b.outputs[0]!]: { block: b.name, port: "emg" } },
        summary: `EmgSimulator, ${channels} channels at ${hz(TRIGNO_NATIVE_RATE)} (a new ScheduledTimer at the Trigno's native rate); gesture keys in the app`,
      };
    },
  },
  DLR_ADCBT: {
    kind: "source",
    network: false,
    becomes: "SinGenerator with one slow (0.5 Hz) sine per channel on its timer",
    substitute(b, env) {
      const timer = timerOf(b)!;
      const n = p(b).Channels as number;
      return {
        blocks: [
          {
            name: b.name,
            type: "SinGenerator",
            params: { Components: n, Amplitude: 1, Frequency: 0.5 },
            inputs: [timer],
          },
        ],
        ports: { analog: { block: b.name, port: "out" } },
        summary: `SinGenerator, ${n} channels at ${hz(env.rateOf(timer.block))} (its timer's)`,
      };
    },
  },
  NilsPod: {
    kind: "source",
    network: false,
    becomes: "ImuSimulator (accelerometer and gyroscope, 6 values) on its timer",
    substitute(b, env) {
      const timer = timerOf(b)!;
      return {
        blocks: [
          {
            name: b.name,
            type: "ImuSimulator",
            params: { Layout: "acc-gyro", Seed: seedOf(b.name) },
            inputs: [timer],
          },
        ],
        ports: { imu: { block: b.name, port: "imu" } },
        summary: `ImuSimulator, 6 values at ${hz(env.rateOf(timer.block))} (its timer's)`,
      };
    },
  },
  BrainFlow: {
    kind: "source",
    network: false,
    becomes:
      "the same BrainFlow block with Simulated: BrainFlow's synthetic board read in the board's channels and at its rate (its EXG, accel and gyro interpolated from 250 Hz); left as it is on the synthetic or playback board; needs the Python sidecar",
    substitute(b) {
      return brainflowSynthetic(b);
    },
  },
  HannesReceiver: {
    kind: "source",
    network: false,
    becomes:
      "EmgSimulator with its channels on its timer (a ScheduledTimer at 100 Hz when it has none)",
    substitute(b, env) {
      const n = p(b).Channels as number;
      const timer = timerOf(b);
      if (timer) return emgOnTimer(b, env, n);
      const clock = env.freshName(`${b.name}_clock`);
      return {
        blocks: [
          { name: clock, type: "ScheduledTimer", params: {}, inputs: [], desiredRate: 100 },
          {
            name: b.name,
            type: "EmgSimulator",
            params: { Channels: n, Seed: seedOf(b.name) },
            inputs: [clock],
          },
        ],
        ports: { [b.outputs[0]!]: { block: b.name, port: "emg" } },
        summary: `EmgSimulator, ${n} channels at 100 Hz (a new ScheduledTimer); gesture keys in the app`,
      };
    },
  },
  ROS: {
    kind: "source",
    network: true,
    becomes:
      "publisher: SimulatedOutput (messages); subscriber: what a publisher of the same pipeline publishes on that topic, else a SinGenerator with its channels at 50 Hz",
    substitute(b, env) {
      const q = p(b);
      const where = `${String(q.Url)} ${String(q.Topic)}`;
      if (q.Direction === "publish") return sink(b, where, "message");
      const channels = (q.Channels as number | undefined) ?? 1;
      const publisher = env.ofType("ROS").find((o) => {
        const r = p(o);
        return (
          o.type === "ROS" &&
          r.Direction === "publish" &&
          r.Topic === q.Topic &&
          r.Url === q.Url &&
          o.inputs.length === 1
        );
      });
      if (publisher) {
        const src = publisher.inputs[0]!;
        return {
          blocks: [
            {
              name: b.name,
              type: "Function",
              params: { Operation: "add", Value: 0 },
              inputs: [{ ...src, subscribed: true }],
            },
          ],
          summary: `what ${publisher.name} publishes on ${String(q.Topic)} (${src.source}, passed through a Function add 0), as through a local rosbridge`,
        };
      }
      const throttle = q.ThrottleMs as number | undefined;
      const rate = throttle !== undefined && throttle > 0 ? 1000 / throttle : 50;
      const clock = env.freshName(`${b.name}_clock`);
      return {
        blocks: [
          { name: clock, type: "ScheduledTimer", params: {}, inputs: [], desiredRate: rate },
          {
            name: b.name,
            type: "SinGenerator",
            params: { Components: channels, Amplitude: 1, Frequency: 0.5 },
            inputs: [clock],
          },
        ],
        summary: `SinGenerator, ${channels} channels at ${hz(rate)} (a new ScheduledTimer; nothing in this pipeline publishes ${String(q.Topic)})`,
      };
    },
  },
  BlenderArm: {
    kind: "output",
    network: true,
    becomes: "SimulatedOutput (datagrams)",
    substitute: (b) => sink(b, endpoint(p(b).Host, p(b).Port), "datagram"),
  },
  HannesGUI: {
    kind: "output",
    network: true,
    becomes: "SimulatedOutput (datagrams)",
    substitute: (b) => sink(b, endpoint(p(b).Host, p(b).Port), "datagram"),
  },
  HannesHand: {
    kind: "output",
    network: false,
    becomes: "SimulatedOutput (commands); left as it is when its reference output is used",
    substitute(b, env) {
      if (b.outputs.some((o) => env.consumed(b.name, o))) {
        return "its reference output is used by other blocks, which a SimulatedOutput does not have";
      }
      const port = p(b).Port;
      return sink(b, typeof port === "string" ? port : "", "command");
    },
  },
  UdpSender: {
    kind: "output",
    network: true,
    becomes:
      "SimulatedOutput (datagrams); kept when a UdpReceiver of the same pipeline listens on its port",
    substitute(b, env) {
      const q = p(b);
      const self = env
        .ofType("UdpReceiver")
        .find(
          (o) =>
            p(o).Port === q.Port &&
            LOOPBACK.test(String(q.Host)) &&
            (LOOPBACK.test(String(p(o).Host)) || p(o).Host === q.Host),
        );
      if (self) return `its datagrams go to ${self.name}, a UdpReceiver of this pipeline`;
      // The control serializer sends one datagram per value (per input, as the sender chooses).
      const counts = b.inputs.map((i) =>
        q.Format === "streamlined" &&
        (q.Serializer === "control" ||
          (q.Serializer === "auto" && env.spec.byName.get(i.block)?.type === "ControlAlgorithm"))
          ? ("values" as const)
          : ("events" as const),
      );
      return sink(b, endpoint(q.Host, q.Port), "datagram", counts);
    },
  },
  SerialPort: {
    kind: "output",
    network: false,
    becomes:
      "SimulatedOutput (frames) when it only writes; a SerialPort whose readings are used is left as it is",
    substitute(b, env) {
      if (env.consumed(b.name)) {
        return "what a serial device sends (its data and rate) cannot be simulated in general; without the port the block says so and the rest of the pipeline runs";
      }
      if (b.inputs.length === 0) return "it neither writes nor is read";
      return sink(b, String(p(b).Path ?? ""), "frame");
    },
  },
};

/** The output of `simulateDevices`. */
export interface SimulationResult {
  spec: PipelineSpec;
  /** One info line per device block (what it became, or why it was left). */
  diagnostics: Diagnostic[];
  /** The blocks substituted, by name. */
  substituted: string[];
}

/**
 * Applies the table to every block of `spec` (see the file comment). Returns a new spec (the input
 * spec is not changed) and one info diagnostic per device block.
 */
export function simulateDevices(
  spec: PipelineSpec,
  catalog: Catalog,
  options: SimulateOptions = {},
): SimulationResult {
  const env = simulationEnv(spec, options.keepNetwork === true);
  // Copies, so that the caller's spec stays as loaded.
  const blocks: BlockSpec[] = spec.blocks.map((b) => ({
    ...b,
    inputs: b.inputs.map((i) => ({ ...i })),
  }));
  const { out, portMaps, diagnostics, substituted } = substituteDevices(blocks, env, catalog);
  const byName = rewireInputs(out, portMaps);
  return { spec: { ...spec, blocks: out, byName }, diagnostics, substituted };
}

/** Where each output port of a substituted device now comes from, by the device's name. */
type PortMaps = Map<string, Record<string, { block: string; port: string }>>;

/** What the rules may ask about `spec`; `freshName` reserves the names it hands out. */
function simulationEnv(spec: PipelineSpec, keepNetwork: boolean): SimulationEnv {
  const names = new Set(spec.blocks.map((b) => b.name));
  const { read, byType } = indexOf(spec);
  return {
    spec,
    keepNetwork,
    rateOf: (block) => spec.byName.get(block)?.desiredRate,
    freshName(base) {
      let n = base;
      for (let i = 2; names.has(n); i++) n = `${base}${i}`;
      names.add(n);
      return n;
    },
    consumed: (block, port) => read.has(port === undefined ? block : `${block}.${port}`),
    ofType: (type) => byType.get(type) ?? [],
  };
}

/** The info line of one device block, at the block. */
function simulatedInfo(spec: PipelineSpec, b: BlockSpec, message: string): Diagnostic {
  return {
    severity: "info",
    code: "simulated-device",
    message,
    file: spec.file,
    line: b.pos.line,
    col: b.pos.col,
    block: b.name,
  };
}

/**
 * Puts each device block's replacement in its place, in file order (blocks without a rule, kept
 * network blocks and those a rule leaves are kept as they are), with one info line per device.
 */
function substituteDevices(
  blocks: BlockSpec[],
  env: SimulationEnv,
  catalog: Catalog,
): { out: BlockSpec[]; portMaps: PortMaps; diagnostics: Diagnostic[]; substituted: string[] } {
  const diagnostics: Diagnostic[] = [];
  const substituted: string[] = [];
  const out: BlockSpec[] = [];
  const portMaps: PortMaps = new Map();
  const info = (b: BlockSpec, message: string): void => {
    diagnostics.push(simulatedInfo(env.spec, b, message));
  };
  for (const b of blocks) {
    const rule = Object.hasOwn(SIMULATED_DEVICES, b.type) ? SIMULATED_DEVICES[b.type] : undefined;
    if (!rule || (env.keepNetwork && rule.network)) {
      out.push(b);
      continue;
    }
    const r = rule.substitute(b, env);
    if (typeof r === "string") {
      info(b, `block '${b.name}' (${b.type}) is not simulated: ${r}`);
      out.push(b);
      continue;
    }
    for (const nb of r.blocks) out.push(newBlock(nb, b, catalog));
    portMaps.set(b.name, r.ports ?? {});
    substituted.push(b.name);
    const verb = r.blocks.some((nb) => nb.type === "SimulatedOutput")
      ? "replaced by"
      : "simulated by";
    info(b, `block '${b.name}' (${b.type}) ${verb} ${r.summary}`);
  }
  return { out, portMaps, diagnostics, substituted };
}

/**
 * Points the inputs that named a substituted block at where its ports now come from (in place),
 * and gives a new block's inputs their default port. Returns the blocks by name.
 */
function rewireInputs(out: BlockSpec[], portMaps: PortMaps): Map<string, BlockSpec> {
  const byName = new Map(out.map((b) => [b.name, b]));
  for (const b of out) {
    for (const inp of b.inputs) rewireInput(inp, byName, portMaps);
  }
  return byName;
}

/** One input of `rewireInputs`. */
function rewireInput(
  inp: InputRef,
  byName: ReadonlyMap<string, BlockSpec>,
  portMaps: PortMaps,
): void {
  // A new block's inputs name blocks: their default port.
  if (inp.port === "") inp.port = byName.get(inp.block)?.outputs[0] ?? "out";
  const map = portMaps.get(inp.block);
  if (!map) return;
  const to = map[inp.port] ?? {
    block: inp.block,
    port: byName.get(inp.block)?.outputs[0] ?? "out",
  };
  if (to.block === inp.block && to.port === inp.port) return;
  const target = byName.get(to.block);
  inp.block = to.block;
  inp.port = to.port;
  inp.source = target && target.outputs[0] === to.port ? to.block : `${to.block}.${to.port}`;
}

/** The BlockSpec of a substitution's block: validated params, the device's place in the file. */
function newBlock(nb: NewBlock, device: BlockSpec, catalog: Catalog): BlockSpec {
  const def: AnyBlockDefinition | undefined = catalog.get(nb.type);
  if (!def) throw new Error(`simulated devices: no block type '${nb.type}' in the catalog`);
  const parsed = def.params.safeParse(nb.params);
  if (!parsed.success) {
    throw new Error(
      `simulated devices: params of ${nb.type} for '${device.name}' are invalid: ${parsed.error.issues[0]?.message ?? ""}`,
    );
  }
  const outputs = outputNames(def, parsed.data);
  const inputs: InputRef[] = nb.inputs.map((i) =>
    typeof i === "string"
      ? { source: i, block: i, port: "", subscribed: true, pos: device.inputsPos }
      : { ...i },
  );
  const carriesName = nb.name === device.name;
  return {
    name: nb.name,
    type: def.type,
    def,
    params: parsed.data,
    desiredRate: nb.desiredRate ?? (carriesName ? device.desiredRate : undefined),
    inputs,
    path: carriesName && outputs.length > 0 ? device.path : undefined,
    worker: device.worker,
    batchingMs: device.batchingMs,
    queue: carriesName ? device.queue : { policy: "drop-oldest", capacity: undefined },
    layout: carriesName ? device.layout : undefined,
    outputs,
    legacy: false,
    pos: device.pos,
    paramsPos: device.paramsPos,
    inputsPos: device.inputsPos,
    paramPos: {},
  };
}

/**
 * A loader's result with its devices simulated (`options` undefined: unchanged): the info lines
 * join the diagnostics. What every host calls after `loadPipeline` when simulation is on.
 */
export function withSimulatedDevices(
  loaded: LoadResult,
  catalog: Catalog,
  options: SimulateOptions | undefined,
): LoadResult {
  if (!options || !loaded.spec) return loaded;
  const s = simulateDevices(loaded.spec, catalog, options);
  return { ...loaded, spec: s.spec, diagnostics: [...loaded.diagnostics, ...s.diagnostics] };
}

/** What the pipeline's inputs read ("Block" and "Block.port") and its blocks by type. */
function indexOf(spec: PipelineSpec): {
  read: Set<string>;
  byType: Map<string, BlockSpec[]>;
} {
  const read = new Set<string>();
  const byType = new Map<string, BlockSpec[]>();
  for (const b of spec.blocks) {
    for (const i of b.inputs) {
      read.add(i.block);
      read.add(`${i.block}.${i.port}`);
    }
    const list = byType.get(b.type);
    if (list) list.push(b);
    else byType.set(b.type, [b]);
  }
  return { read, byType };
}
