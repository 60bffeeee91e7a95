/**
 * Contract tests over every block of the catalog (CONVENTIONS.md, after fundsp/biquad-rs): the
 * params validate and produce a JSON Schema with every param described; one frame of N events
 * gives the same output, bit for bit, as N frames of one event; after `reset` the output repeats;
 * `dispose()` twice is harmless; and garbage params, loaded through the loader and the runtime
 * like a pipeline file, are refused with a zod issue, a LegacyParamsError or a BlockConfigError —
 * never a TypeError or RangeError from deep inside (nor one at run time, from an action or a live
 * param). A block missing from the table below fails the test, so every new block gets a setup.
 *
 * This is the same contract as `mosaic test-block FILE` runs on a user's blocks: its program,
 * app/engine/block-contract.ts, gives the events, the feeding, the snapshots, the guarded
 * definitions and the garbage pipelines used here, and the test "mosaic test-block's checks"
 * runs that program (`runBlockContract`) on every block with the setups below. What is only here:
 * the stricter docs (panel, help length), the fast-check garbage and the extremes sweep.
 */
import fc from "fast-check";
import { beforeAll, describe, expect, test } from "vitest";
import { z } from "zod";
import { BLOCKS } from "./catalog";
import {
  createCatalog,
  EMPTY_SHAPE,
  loadPipeline,
  matrixShape,
  objectKeys,
  outputNames,
  vectorShape,
  type AnyBlockDefinition,
} from "../engine";
import {
  CHECK_NAMES,
  clearAll,
  describeFailure,
  feedGrouped,
  feedOneByOne,
  harness,
  makeEvents,
  runBlockContract,
  smoothValues,
  noFiles,
  snapshot,
  tryGarbage,
  type BlockSetup,
  type ContractIo,
  type ContractSetup,
  type SetupInput,
} from "../engine/block-contract";
import { BlockHarness } from "../engine/testing";
import { memoryResources } from "../../tests/support/fs-resources";
import { initDspForTests } from "../../tests/support/wasm";

beforeAll(() => initDspForTests());

type InputSetup = SetupInput;

/**
 * A setup of the block contract (app/engine/block-contract.ts: params, inputs, pattern, events,
 * values, resources, silent, fuzzKeep, io), with what only this test knows.
 */
interface Setup extends BlockSetup {
  params: unknown;
  inputs: InputSetup[];
  /**
   * Known internal errors under garbage params (reported, in files this test does not own): a
   * failure whose text matches is tolerated; the extremes test fails once none matches any more,
   * so that the entry is removed when the block is fixed.
   */
  known?: { pattern: RegExp; reason: string }[];
}

type FakeIo = ContractIo;

/** A UDP bridge that keeps every datagram sent (as hex), instead of a socket. */
function recordingUdp(): FakeIo {
  const sent: string[] = [];
  return {
    io: {
      udp: {
        open: () => ({
          send: (data) => sent.push(Buffer.from(data).toString("hex")),
          close: () => {},
        }),
      },
    },
    recorded: () => [...sent],
    clear: () => (sent.length = 0),
  };
}

/** A serial device that echoes every byte written to it (a loopback plug); writes are recorded. */
function loopbackSerial(): FakeIo {
  const written: string[] = [];
  return {
    io: {
      serial: {
        open: (o) => {
          o.onStatus("open");
          return {
            write: (data) => {
              written.push(Buffer.from(data).toString("hex"));
              o.onData(data);
            },
            close: () => o.onStatus("closed"),
          };
        },
        list: async () => [],
      },
    },
    recorded: () => [...written],
    clear: () => (written.length = 0),
  };
}

/**
 * A Python sidecar that answers at once (synchronously, inside `call`): `Function(x, state)` adds
 * the number of calls since `init` to every value (a state that `reset` clears); the calls are
 * recorded.
 */
function instantPython(): FakeIo {
  const calls: number[] = [];
  return {
    io: {
      python: {
        load: (o) => {
          let n = 0;
          let id = 0;
          const out = new Float64Array(o.inputShape.rows * o.inputShape.cols);
          o.onStatus("ready");
          return Promise.resolve({
            outputShape: o.inputShape,
            pid: 1,
            version: "fake",
            ready: true,
            call: (values) => {
              n++;
              calls.push(values.length);
              for (let i = 0; i < out.length; i++) out[i] = values[i]! + n;
              o.onResult(++id, out, 1);
              return id;
            },
            reset: () => (n = 0),
            close: () => o.onStatus("closed"),
          });
        },
      },
    },
    recorded: () => [...calls],
    clear: () => (calls.length = 0),
  };
}

/**
 * A rosbridge that connects at once and loops every published message back to the subscriptions
 * of the same topic (as a ROS graph would); the messages are recorded as JSON.
 */
function loopbackRos(): FakeIo {
  const sent: string[] = [];
  const subs = new Map<string, ((msg: unknown) => void)[]>();
  return {
    io: {
      ros: {
        connect: (o) => {
          o.onState("connecting");
          o.onState("connected");
          return {
            advertise: ({ topic }) => ({
              publish: (msg) => {
                const text = JSON.stringify(msg);
                sent.push(`${topic} ${text}`);
                for (const f of subs.get(topic) ?? []) f(JSON.parse(text));
                return true;
              },
              unadvertise: () => {},
            }),
            subscribe: ({ topic, onMessage }) => {
              subs.set(topic, [...(subs.get(topic) ?? []), onMessage]);
              return { unsubscribe: () => subs.delete(topic) };
            },
            close: () => {},
          };
        },
      },
    },
    recorded: () => [...sent],
    clear: () => (sent.length = 0),
  };
}

/**
 * A Bluetooth adapter with one Myo armband in range: it connects and accepts the Myo block's
 * commands, but sends no notification (live data would not repeat after `reset`), so a paced Myo
 * emits zeros until its first sample, as MOSAIC's did. Nothing is recorded for the same reason:
 * the commands are written once, at start (myo.test.ts checks them).
 */
function quietMyo(): FakeIo {
  const myo = (short: number): string =>
    `d506${short.toString(16).padStart(4, "0")}a904deb947482c7f4a124842`;
  const characteristics = [
    [0x0001, 0x0401],
    [0x0002, 0x0402],
    [0x0005, 0x0105],
    [0x0005, 0x0205],
    [0x0005, 0x0305],
    [0x0005, 0x0405],
  ].map(([s, c]) => ({ service: myo(s!), uuid: myo(c!), properties: ["notify", "write"] }));
  return {
    io: {
      ble: {
        watchState: (onChange) => {
          onChange("poweredOn");
          return { close: () => {} };
        },
        scan: (o) => {
          o.onFound({ address: "aa:bb:cc:dd:ee:01", name: "Myo", services: [myo(1)] });
          return { stop: () => {} };
        },
        connect: async (address) => ({
          address,
          discover: async () => characteristics,
          subscribe: async () => {},
          write: async () => {},
          disconnect: () => {},
        }),
      },
    },
    recorded: () => [],
    clear: () => {},
  };
}

const timer = (rate: number): InputSetup => ({ shape: EMPTY_SHAPE, rate, isTimer: true });
const vec = (c: number, rate = 100): InputSetup => ({ shape: vectorShape(c), rate });
const mat = (r: number, c: number, rate = 100): InputSetup => ({ shape: matrixShape(r, c), rate });

const RECORDING = "time_s,a,b\n0,1,-1\n0.01,2,-2\n0.02,3.5,0.25\n0.03,-4,1e-3\n0.04,5,NaN\n";

const smooth = smoothValues;

/** A feature block on window matrices, and on a plain stream that it windows itself. */
const feature = (params: object = {}): Setup[] => [
  { params, inputs: [mat(10, 3)] },
  { params: { ...params, Window: 5, Hop: 2 }, inputs: [vec(2)] },
];

/**
 * A valid setup for every block type of the catalog (several for blocks whose behaviour depends
 * much on a param).
 */
const SETUPS: Record<string, Setup | Setup[]> = {
  ScheduledTimer: { params: {}, inputs: [] },
  DecimatorTimer: { params: {}, inputs: [timer(200)] },
  SinGenerator: {
    params: { Components: 3, Frequency: 7 },
    inputs: [timer(100)],
  },
  EmgSimulator: {
    params: {
      Channels: 6,
      Sequence: [
        { Gesture: "fist", Seconds: 0.004 },
        { Gesture: "rest", Seconds: 0.003 },
        { Gesture: "pinch", Seconds: 0.005 },
      ],
    },
    inputs: [timer(1000)],
    events: 60,
  },
  FilePlayer: {
    params: { File: "r.csv", Loop: true },
    inputs: [timer(100)],
    resources: memoryResources({ "r.csv": RECORDING }),
  },
  Function: {
    params: { Operation: "multiply" },
    inputs: [mat(2, 3), vec(3)],
    pattern: [0, 0, 1, 0, 1, 1, 0, 0, 0],
  },
  Amplification: { params: { Gain: [1, -2, 0.5] }, inputs: [mat(2, 3)] },
  Rectification: { params: {}, inputs: [vec(4)] },
  Filter: {
    params: { Numerator: [0.2, 0.3, 0.1], Denominator: [1, -0.6, 0.2] },
    inputs: [vec(4)],
  },
  LinearMap: { params: { Outputs: 3, Bias: [1, 2, 3] }, inputs: [vec(5)] },
  AdaptiveFilter: [
    { params: {}, inputs: [vec(3, 200)] },
    { params: { UseTimestamps: true, Derivative: "mosaic", G1: 2 }, inputs: [vec(2, 200)] },
  ],
  ddS: [
    { params: { Rows: 4, Columns: 2 }, inputs: [vec(8)] },
    {
      params: { Rows: 2, Columns: 3, Direction: "columns", Layout: "column-major" },
      inputs: [mat(3, 6)],
    },
  ],
  MeanAbsoluteValue: feature(),
  RMS: feature(),
  WaveformLength: feature(),
  ZeroCrossings: feature({ Threshold: 0.1 }),
  SlopeSignChanges: feature({ Threshold: 0.05 }),
  Variance: feature(),
  IntegratedAbsoluteValue: feature(),
  DASDV: feature(),
  WillisonAmplitude: feature({ Threshold: 0.2 }),
  FeatureSet: [
    { params: {}, inputs: [mat(8, 2)] },
    {
      params: { Features: ["RMS", "WAMP", "SSC"], WAMPThreshold: 0.2, Window: 4, Hop: 3 },
      inputs: [vec(3)],
    },
  ],
  BodyRig: [
    { params: {}, inputs: [vec(12)] },
    {
      // Two inputs, Euler angles, the Trigger on the second; every 7th event (NaN) is refused.
      params: {
        Orientation: "euler",
        EulerSequence: "xyz",
        Output: "matrix",
        Trigger: "in1",
        Links: [
          { Name: "Torso", Offset: [0, 0, 0.5], SensorToSegmentEuler: [0, 90, 0] },
          { Name: "Arm", Parent: "Torso", Length: 0.3, Input: "in1", Channel: 1 },
          { Name: "Hand", Parent: "Arm", Length: 0.1, Axis: "-z", Input: "in1" },
        ],
      },
      inputs: [vec(3), vec(7)],
      pattern: [0, 1, 1, 0, 1, 0, 0, 1],
      values: (i, port, size) =>
        i % 7 === 3 ? new Array<number>(size).fill(NaN) : smooth(i, port, size),
    },
    { params: { Links: [{ Name: "Shank", Length: 0.4, Axis: "-y" }] }, inputs: [vec(4)] },
  ],
  SlidingWindow: [
    { params: { Length: 5, Step: 2 }, inputs: [vec(3)] },
    { params: { Length: 4, WindowFunction: "hann" }, inputs: [vec(2)] },
  ],
  ArtifactRejection: [
    { params: {}, inputs: [mat(20, 3)] },
    {
      params: { Mode: "soft", RailLow: -2, RailHigh: 2, DriftThreshold: 0.5 },
      inputs: [mat(6, 2)],
    },
  ],
  VectorialFunction: [
    {
      params: { Operation: "subtract" },
      inputs: [mat(2, 3), vec(3)],
      pattern: [0, 1, 0, 0, 1, 1, 0],
    },
    { params: { Operation: "rotate", Roll: 0.3, Pitch: -1, Yaw: 2 }, inputs: [vec(6)] },
    { params: { Operation: "norm" }, inputs: [mat(3, 2)] },
    { params: { Operation: "integrate" }, inputs: [mat(2, 2)] },
    { params: { Operation: "integrate", Integration: "sum" }, inputs: [vec(3)] },
    { params: { Operation: "cross" }, inputs: [vec(3), vec(3)], pattern: [1, 0, 0, 1, 0] },
    { params: { Operation: "dot" }, inputs: [mat(2, 4), vec(4)], pattern: [0, 1, 1, 0, 0] },
    {
      params: {
        Operation: "matmul",
        Matrix: [
          [1, 2],
          [3, 4],
          [5, 6],
        ],
      },
      inputs: [vec(2)],
    },
    { params: { Operation: "wrench" }, inputs: [vec(6), vec(3)], pattern: [1, 0, 0, 1, 0, 1] },
  ],
  Resampler: {
    params: { Mode: "mean" },
    inputs: [vec(3), timer(25)],
    pattern: [0, 0, 1, 1, 0, 0, 0, 1, 0, 1, 1, 1],
  },
  Joiner: {
    params: { Trigger: "in2" },
    inputs: [vec(2), timer(50), vec(3)],
    pattern: [1, 0, 2, 2, 1, 0, 0, 2, 1, 1, 2],
  },
  Splitter: { params: { Parts: { a: [3, 0], b: [1, 1, 2] } }, inputs: [vec(4)] },
  Projector: { params: { Indices: [2, 0, 2] }, inputs: [mat(3, 3)] },
  Buffer: [
    {
      params: { Stream: true },
      inputs: [vec(2), vec(3, 25)],
      pattern: [1, 0, 1, 1, 0, 0, 1, 1, 1],
      // Every third trigger event stops (all NaN); the others alternate two targets.
      values: (i, port, size) =>
        port === 0
          ? i % 3 === 0
            ? [NaN, NaN]
            : i % 2 === 0
              ? [1, 0]
              : [0, 1]
          : smooth(i, port, size),
    },
    {
      params: { Stream: true, MaxRows: 7 },
      inputs: [vec(1), mat(2, 2)],
      pattern: [0, 1, 1, 1, 0, 1, 1],
    },
  ],
  ChannelSelector: [
    { params: { Active: [0, 2], Inactive: "hold" }, inputs: [mat(2, 3)] },
    { params: { Active: [1], Inactive: "nan" }, inputs: [vec(3)] },
  ],
  Selector: [
    { params: { Row: -1, Columns: [2, 0] }, inputs: [mat(3, 3)] },
    { params: {}, inputs: [vec(3)] },
  ],
  Switch: {
    params: { Active: 1 },
    inputs: [vec(2), vec(2, 50), vec(2, 10)],
    pattern: [0, 1, 1, 2, 0, 1, 2, 2],
  },
  Logger: {
    params: { Folder: "logs" },
    inputs: [vec(2), timer(10), mat(2, 2)],
    pattern: [0, 1, 1, 2, 0, 2],
  },
  Sink: { params: {}, inputs: [vec(2), timer(10)], pattern: [0, 1, 1], silent: true },
  // Without a file host (openWrite) it says so and records nothing (tests/integration/edf.test.ts);
  // input 2 (aperiodic) is a marker input.
  EdfRecorder: {
    params: { File: "rec.edf" },
    inputs: [vec(2), mat(2, 2), vec(1, 0)],
    pattern: [0, 1, 1, 0, 2],
    silent: true,
  },
  // Without a file host (openWrite) it says so and records nothing (tests/integration/xdf.test.ts).
  XdfRecorder: {
    params: { File: "rec.xdf" },
    inputs: [vec(2), mat(2, 2)],
    pattern: [0, 1, 1, 0],
    silent: true,
  },
  ControlAlgorithm: {
    params: { Strategy: "stepwise", SlewRate: 50, Timeout: 0 },
    inputs: [vec(3)],
  },
  UdpSender: [
    { params: { Port: 9 }, inputs: [vec(3)], io: recordingUdp },
    {
      params: { Port: 9, Serializer: "control", Subcategories: [0, 8, 10] },
      inputs: [vec(3)],
      io: recordingUdp,
    },
    {
      params: { Port: 9, Serializer: "myo", Timestamp: "event" },
      inputs: [vec(4)],
      io: recordingUdp,
    },
    { params: { Host: "::1", Port: 9, Format: "f32" }, inputs: [mat(2, 2)], io: recordingUdp },
  ],
  // Paced by a timer (MOSAIC's form); fed by the armband's notifications alone in the second.
  Myo: [
    { params: {}, inputs: [timer(200)], io: quietMyo },
    { params: { Address: "AA:BB:CC:DD:EE:01", EMG: "raw", IMU: false }, inputs: [], io: quietMyo },
  ],
  BlenderArm: [
    { params: { Port: 9 }, inputs: [vec(11)], io: recordingUdp },
    { params: { Port: 9 }, inputs: [vec(12)], io: recordingUdp },
    { params: { Port: 9, Input: "command" }, inputs: [vec(9)] },
  ],
  HannesGUI: [
    {
      params: { Port: 9 },
      inputs: [vec(11), vec(8, 200), vec(8, 25)],
      pattern: [0, 1, 1, 2, 0, 1],
      io: recordingUdp,
    },
    { params: { Port: 9, Input: "prediction" }, inputs: [vec(13)], io: recordingUdp },
  ],
  // Without a serial bridge: the references still go out (the handshake is in hannes.test.ts).
  HannesHand: { params: { Port: "/dev/ttyACM0" }, inputs: [vec(11)] },
  // Fed by its socket (hannes.test.ts): paced, it repeats zeros here.
  HannesReceiver: [
    { params: { Port: 9 }, inputs: [timer(100)] },
    { params: { Port: 9, Channels: 8 }, inputs: [] },
  ],
  // The original's timer-paced devices (app/blocks/devices/): no protocol yet, they send zeros.
  Muovi: { params: { Probes: [0, 2] }, inputs: [timer(100)] },
  MuoviSingleProbe: [
    { params: {}, inputs: [timer(1000)] },
    { params: { Probes: [1] }, inputs: [timer(2000)] },
  ],
  Delsys: { params: { Sensors: 4 }, inputs: [timer(1926)] },
  // Without a TCP bridge it says so and sends nothing (tests/integration/sessantaquattro.test.ts
  // streams it).
  Sessantaquattro: [
    { params: {}, inputs: [], silent: true },
    {
      params: { Model: "Sessantaquattro+", Channels: 8, HighRes: true, Extras: false },
      inputs: [],
      silent: true,
    },
  ],
  // Without a TCP bridge it says so and sends nothing (tests/integration/quattrocento.test.ts streams it).
  Quattrocento: [
    { params: {}, inputs: [], silent: true },
    {
      params: { Connectors: ["IN1", "AUX IN"], Select: [1, 17], Unit: "raw" },
      inputs: [],
      silent: true,
    },
  ],
  DLR_ADCBT: { params: { Port: "COM5", Channels: 3 }, inputs: [timer(100)] },
  NilsPod: { params: {}, inputs: [timer(100)] },
  // Without the Python sidecar it says Python is needed and sends nothing
  // (tests/integration/brainflow.test.ts streams the synthetic and playback boards).
  BrainFlow: { params: { Board: "SYNTHETIC_BOARD" }, inputs: [], silent: true },
  ImuSimulator: [
    { params: {}, inputs: [timer(100)] },
    { params: { Layout: "myo", NoiseStd: 0 }, inputs: [timer(50)] },
  ],
  SimulatedOutput: [
    {
      params: { Device: "BlenderArm", Destination: "localhost:3334", Unit: "datagram" },
      inputs: [vec(11)],
      silent: true,
    },
    {
      params: { Device: "UdpSender", Count: "values" },
      inputs: [vec(3), mat(2, 2)],
      pattern: [0, 1, 1, 0],
      silent: true,
    },
  ],
  // Without the LSL bridge here (the browser build's case): they say so and send nothing
  // (tests/integration/lsl.test.ts runs them against liblsl and pylsl).
  LslOutlet: { params: { Name: "EMG", Format: "int16" }, inputs: [vec(4)], silent: true },
  LslMarkers: { params: { Labels: ["rest", "power"] }, inputs: [vec(1)], silent: true },
  LslInlet: { params: { Name: "EMG", Channels: 8 }, inputs: [] },
  LslMarkerInlet: { params: { Type: "Markers" }, inputs: [] },
  // A source fed by its socket: nothing to feed here (tests/integration/udp.test.ts runs it).
  UdpReceiver: { params: { Port: 9, Channels: 3 }, inputs: [] },
  SerialPort: [
    { params: { Path: "/dev/ttyUSB0", Channels: 3 }, inputs: [] },
    {
      params: { Path: "/dev/ttyUSB0", Framing: "binary", Fields: ["i16", "f32"], Sync: [170, 85] },
      inputs: [vec(2)],
      io: loopbackSerial,
    },
    {
      params: { Path: "COM3", Channels: 2, Checksum: "none" },
      inputs: [vec(2)],
      io: loopbackSerial,
    },
  ],
  ROS: [
    { params: { Topic: "/mosaic/out" }, inputs: [vec(3)], io: loopbackRos },
    {
      params: { Topic: "/m", MessageType: "std_msgs/Float32MultiArray" },
      inputs: [mat(2, 2)],
      io: loopbackRos,
    },
    {
      params: { Topic: "cmd_vel", MessageType: "geometry_msgs/Twist" },
      inputs: [vec(6)],
      io: loopbackRos,
    },
    {
      params: { Topic: "/j", MessageType: "sensor_msgs/JointState", JointNames: ["a", "b"] },
      inputs: [vec(2)],
      io: loopbackRos,
    },
    // A source fed by its connection: nothing to feed here (tests/integration/ros.test.ts runs it).
    { params: { Topic: "/in", Direction: "subscribe", Channels: 2 }, inputs: [], io: loopbackRos },
  ],
  Python: [
    { params: { Module: "m.py", Function: "f" }, inputs: [vec(3)], io: instantPython },
    {
      params: { Module: "m.py", Function: "f", Init: "init", Params: { a: 1 }, OnError: "skip" },
      inputs: [mat(4, 2, 25)],
      io: instantPython,
    },
    // Without a bridge (the browser build): loads, says so, emits nothing.
    {
      params: { Module: "mymodule", Function: "f", OutputShape: [1, 2] },
      inputs: [vec(3)],
      silent: true,
    },
  ],
  // Python-backed blocks: their own output shapes do not fit the fake sidecar (which echoes its
  // input's), so without a bridge (tests/integration/python-blocks.test.ts runs the real one).
  PythonNetFiltUC: [
    { params: { Frequency: 5 }, inputs: [vec(3)], io: instantPython },
    {
      params: { Filter: "notch", Q: 2, Frequency: 10, SampleRate: 200 },
      inputs: [mat(4, 2, 50)],
      silent: true,
    },
  ],
  PythonNetLearning: {
    params: { Buffer: "b", Method: "lda-predict" },
    inputs: [vec(3)],
    silent: true,
  },
  SimplePyTorch: { params: {}, inputs: [vec(5)], silent: true },
  iNMF: [
    { params: { Synergies: 2 }, inputs: [vec(4)], silent: true },
    {
      params: { Synergies: 2, Outputs: 12 },
      inputs: [mat(5, 4), vec(4)],
      pattern: [0, 1, 1],
      silent: true,
    },
  ],
  // Setups that end idle (no capture or trial in progress): `reset` would send the stop.
  Trigger: {
    params: {
      Labels: { rest: [0, 0], fist: [1, 0], open: [0, 1] },
      Initial: "fist",
      Condition: { Channel: 1, Above: 0.5 },
      Schedule: { Sequence: ["open", "rest"], Seconds: 0.01, Pause: 0.005, Repetitions: 2 },
    },
    inputs: [vec(2)],
    values: (i) => [Math.sin(i), i % 7 < 3 ? 1 : 0],
  },
  Stimulus: [
    {
      params: {
        Labels: { rest: [0, 0], fist: [1, 0], open: [0, 1] },
        Tasks: ["fist", "open", { Label: "pinch", Target: [1, 1] }],
        Rest: 0.002,
        Rise: 0.002,
        Hold: 0.001,
        Capture: 0.003,
        Fall: 0.002,
        Autostart: true,
      },
      inputs: [timer(1000)],
    },
    {
      params: {
        Tasks: [
          { Label: "a", Target: [1] },
          { Label: "b", Target: [2] },
        ],
        Repetitions: 2,
        Shuffle: true,
        Rest: 0.001,
        Rise: 0,
        Hold: 0,
        Capture: 0.005,
        Fall: 0.001,
        Autostart: true,
      },
      inputs: [timer(1000), vec(1, 10)],
      pattern: [0, 0, 0, 1],
    },
  ],
  StimTrigger: {
    params: {},
    inputs: [vec(2, 0)],
    values: (i) => (i % 4 === 3 ? [NaN, NaN] : [1, i % 2]),
  },
  TAC: [
    {
      params: {
        Targets: [
          [0.5, -0.5],
          [0, 0.2],
          [1, 1],
        ],
        Tolerance: 0.5,
        Dwell: 0.002,
        TimeLimit: 0.008,
        Pause: 0.001,
        Autostart: true,
      },
      inputs: [vec(2)],
    },
    {
      params: {
        Tolerance: [0.6, 1],
        Metric: "box",
        Dwell: 0.002,
        TimeLimit: 0.006,
        Autostart: true,
      },
      inputs: [vec(2), vec(2, 10)],
      pattern: [1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0],
      // Targets at events 0 and 22, all NaN (end of trial) at 11 and 33.
      values: (i, port, size) =>
        port === 1 ? (i % 22 === 0 ? [0.5, 0] : [NaN, NaN]) : smooth(i, port, size),
    },
  ],
  IncrementalPredictor: [
    {
      params: { Lambda: 0.1 },
      inputs: [vec(3), vec(2, 10)],
      pattern: [1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0],
      // Targets, with an all-NaN stop every 10th event.
      values: (i, port, size) =>
        port === 1 ? (i % 10 === 0 ? [NaN, NaN] : [Math.sin(i), 1]) : smooth(i, port, size),
    },
    {
      params: {
        Model: "rff",
        Features: 16,
        Gamma: 0.2,
        Normalize: true,
        NormalizeSamples: 5,
        Forgetting: 0.95,
      },
      inputs: [vec(4), vec(1, 10)],
      pattern: [1, 0, 0, 0, 1, 0, 0],
      values: (i, port, size) =>
        port === 1 ? (i % 14 === 4 ? [NaN] : [i / 10]) : smooth(i, port, size),
    },
    {
      // LDA: two classes (one-hot targets) with an all-NaN stop every 9th event.
      params: { Model: "lda", Shrinkage: 0.1 },
      inputs: [vec(3), vec(2, 10)],
      pattern: [1, 0, 0, 1, 0, 0, 0],
      values: (i, port, size) =>
        port === 1
          ? i % 9 === 0
            ? [NaN, NaN]
            : i % 2 === 0
              ? [1, 0]
              : [0, 1]
          : smooth(i, port, size),
    },
    {
      // Predicting only, with a model file: one sample x = (1, 2), y = 3, λ 1, no intercept.
      params: { File: "m.json" },
      inputs: [vec(2)],
      resources: memoryResources({
        "m.json": JSON.stringify({
          format: "mosaic-model",
          version: 1,
          kind: "ridge",
          inputs: 2,
          outputs: 1,
          lambda: 1,
          forgetting: 1,
          intercept: false,
          normalize: false,
          samplesSeen: 1,
          lambdaEffective: 1,
          model: { weights: [[0.5], [1]], intercept: [0], penalty: [1, 1] },
          state: {
            weightSum: 1,
            xMean: [0, 0],
            yMean: [0],
            scatter: [
              [1, 2],
              [2, 4],
            ],
            cross: [[3], [6]],
            fitStats: { weight: 0, mean: [0], m2: [0], sse: [0] },
          },
        }),
      }),
    },
  ],
  BatchPredictor: [
    {
      // Dataset replace: a frame of rows is a data set, so rows come one frame each here.
      params: { Lambda: 0.5 },
      inputs: [vec(2), vec(3, 5)],
      pattern: [1, 0, 0, 0, 1, 0, 0],
    },
    {
      params: { Model: "rff", Features: 8, Dataset: "append", AutoTrain: false },
      inputs: [vec(2), vec(4, 5)],
      pattern: [1, 1, 0, 0, 1, 0],
    },
  ],
  Busy: {
    params: { Milliseconds: 0, Every: 3 },
    inputs: [vec(2)],
    fuzzKeep: {
      keys: ["Milliseconds"],
      reason: "it spins that long by design (up to 10 s per call would slow the test down)",
    },
  },
};

const setupsOf = (type: string): Setup[] => {
  const s = SETUPS[type];
  return s === undefined ? [] : Array.isArray(s) ? s : [s];
};

/** The catalog the garbage pipelines are made of. */
const CATALOG = createCatalog(BLOCKS);

// Sizes that cannot be allocated (1e12 or more), never ones that merely take seconds (1e8), so
// that a missing bound shows as an error here instead of a slow test.
const NUMBERS = [
  0,
  -0,
  1,
  -1,
  2,
  3,
  0.5,
  -0.5,
  6,
  100,
  65536,
  -1e5,
  1e12,
  1e15,
  1e300,
  -1e300,
  1e-300,
  Number.MAX_SAFE_INTEGER,
  2 ** 53,
  NaN,
  Infinity,
  -Infinity,
];
const STRINGS = [
  "",
  " ",
  "x",
  "in0",
  "in1",
  "Src0",
  "zero",
  "hold",
  "add",
  "multiply",
  "rotate",
  "abs",
  "mean",
  "1;2;3",
  "a:b",
  ".inf",
  "[1, 2]",
  "é\u0000",
];
const weirdNumber = fc.oneof(
  fc.constantFrom(...NUMBERS),
  fc.integer({ min: -20, max: 20 }),
  fc.double({ noDefaultInfinity: false }),
);
const leaf = fc.oneof(
  { weight: 4, arbitrary: weirdNumber },
  { weight: 2, arbitrary: fc.constantFrom(...STRINGS) },
  { weight: 1, arbitrary: fc.string({ maxLength: 10 }) },
  { weight: 1, arbitrary: fc.boolean() },
  { weight: 1, arbitrary: fc.constant(null) },
);
const { anyValue } = fc.letrec((tie) => ({
  anyValue: fc.oneof(
    { depthSize: "small", withCrossShrink: true },
    leaf,
    fc.array(tie("anyValue"), { maxLength: 6 }),
    fc.dictionary(fc.string({ maxLength: 6 }), tie("anyValue"), { maxKeys: 4 }),
  ),
}));
/** Arrays and objects at the extremes: empty, huge, deeply nested. */
const extreme = fc.oneof(
  fc.constant([]),
  fc.constant({}),
  fc.constant(new Array<number>(20_000).fill(1)),
  fc.constant(new Array<number[]>(300).fill([1, 2, 3])),
  fc.constant([new Array<number>(300).fill(0.5)]),
  fc.nat({ max: 40 }).map((d) => {
    let o: unknown = 1;
    for (let i = 0; i < d; i++) o = i % 2 === 0 ? { a: o } : [o];
    return o;
  }),
);
const positional = fc.array(
  fc.oneof(
    fc.constantFrom(
      "multiply:5",
      "abs:0",
      "subtract",
      "rotation:1;2",
      "rotation:1;2;3",
      "matrix_multiply",
      "1;2;3",
      "0.1;0.2, 1;-0.5",
      ":",
      "a:b:c",
      "1e999",
      "-1",
      "NaN",
      "timerBlockName:",
      "rest:0;0;1",
      "",
    ),
    fc.string({ maxLength: 12 }),
  ),
  { maxLength: 5 },
);

function paramsArbitrary(def: AnyBlockDefinition, s: Setup): fc.Arbitrary<unknown> {
  const kept = s.fuzzKeep?.keys ?? [];
  const keys = (objectKeys(def.params) ?? []).filter((k) => !kept.includes(k));
  const base = (s.params ?? {}) as Record<string, unknown>;
  const value = fc.oneof(
    { weight: 3, arbitrary: weirdNumber },
    { weight: 4, arbitrary: anyValue },
    { weight: 1, arbitrary: extreme },
  );
  const options: fc.WeightedArbitrary<unknown>[] = [
    ...(kept.length > 0
      ? []
      : [
          { weight: 2, arbitrary: anyValue },
          { weight: 1, arbitrary: extreme },
        ]),
    { weight: 2, arbitrary: positional },
    {
      weight: 2,
      arbitrary: fc
        .dictionary(fc.constantFrom(...keys, "Unknown", "extra"), value, { maxKeys: 4 })
        .map((d) => ({ ...d, ...Object.fromEntries(kept.map((k) => [k, base[k]])) })),
    },
  ];
  if (keys.length > 0) {
    // The example with one or two of its params replaced by garbage.
    options.push({
      weight: 8,
      arbitrary: fc
        .array(fc.tuple(fc.constantFrom(...keys), value), { minLength: 1, maxLength: 2 })
        .map((kv) => ({ ...base, ...Object.fromEntries(kv) })),
    });
  }
  return fc.oneof(...options);
}

/**
 * The example params with one number param (or one element of a number-list param) set to each
 * extreme value in turn: a deterministic sweep next to the random garbage.
 */
function extremeVariants(def: AnyBlockDefinition, s: Setup): unknown[] {
  const kept = s.fuzzKeep?.keys ?? [];
  const schema = z.toJSONSchema(def.params, { io: "input" }) as {
    properties?: Record<string, unknown>;
  };
  const base = (s.params ?? {}) as Record<string, unknown>;
  const out: unknown[] = [];
  for (const [k, prop] of Object.entries(schema.properties ?? {})) {
    if (kept.includes(k)) continue;
    const text = JSON.stringify(prop);
    const numeric = /"type":"(number|integer)"/.test(text);
    const list = /"type":"array"/.test(text);
    for (const v of NUMBERS) {
      if (numeric) out.push({ ...base, [k]: v });
      if (list) {
        const ex = base[k];
        out.push({ ...base, [k]: Array.isArray(ex) && ex.length > 0 ? [v, ...ex.slice(1)] : [v] });
      }
    }
    if (list) out.push({ ...base, [k]: [] }, { ...base, [k]: new Array<number>(20_000).fill(1) });
  }
  return out;
}

const isKnown = (s: Setup, failure: string): boolean =>
  (s.known ?? []).some((k) => k.pattern.test(failure));

/**
 * Random mixtures of garbage params in the run of `mosaic test-block`'s program below (the CLI
 * tries 60 after its one-param sweep; the fast-check garbage test covers mixtures here).
 */
const PROGRAM_GARBAGE_RUNS = 10;

/** A setup of this table as a module's `contract` export would say it. */
const contractSetup = (s: Setup): ContractSetup => ({
  ...s,
  inputs: s.inputs.map((i) => ({
    shape: [i.shape.rows, i.shape.cols] as const,
    ...(i.rate === undefined ? {} : { rate: i.rate }),
    ...(i.isTimer ? { timer: true } : {}),
  })),
});

describe("block contract", () => {
  test("every catalog block has a setup here", () => {
    const missing = BLOCKS.map((b) => b.type).filter((t) => !(t in SETUPS));
    expect(missing).toEqual([]);
    const unknown = Object.keys(SETUPS).filter((t) => !BLOCKS.some((b) => b.type === t));
    expect(unknown).toEqual([]);
  });

  test("loader: `Params: []` on a block whose positional form needs arguments is a diagnostic", () => {
    const r = loadPipeline(
      "T: { Type: ScheduledTimer, DesiredRate: 10 }\n" +
        "S: { Type: SinGenerator, Inputs: [T] }\n" +
        "P: { Type: Projector, Inputs: [S], Params: [] }\n",
      "t.yaml",
      createCatalog(BLOCKS),
    );
    expect(r.diagnostics.some((d) => d.block === "P")).toBe(true);
  });

  describe.each(BLOCKS.map((def) => [def.type, def] as const))("%s", (type, def) => {
    const setups = setupsOf(type);

    test("docs: summary, help, panel and a description for every param; JSON Schema", () => {
      expect(def.summary.trim()).not.toBe("");
      expect(def.summary).not.toContain("\n");
      expect(def.help.trim().length).toBeGreaterThan(80);
      expect(def.panel?.trim() ?? "").not.toBe("");
      const schema = z.toJSONSchema(def.params, { io: "input" }) as {
        properties?: Record<string, { description?: string }>;
      };
      const keys = objectKeys(def.params) ?? [];
      expect(Object.keys(schema.properties ?? {})).toEqual(keys);
      for (const k of keys) {
        expect(
          schema.properties![k]!.description ?? "",
          `${type}.${k} has no description`,
        ).not.toBe("");
      }
      for (const l of def.live ?? []) expect(keys).toContain(l);
      if (def.legacyParams) expect(def.legacyForm ?? "").not.toBe("");
    });

    test("the setups' params validate and their outputs are declared", async () => {
      expect(setups.length).toBeGreaterThan(0);
      for (const setup of setups) {
        const parsed = def.params.safeParse(setup.params);
        expect(parsed.success, JSON.stringify(parsed.error?.issues)).toBe(true);
        const h = await harness(def, setup);
        expect(h.ports.map((p) => p.name)).toEqual([...outputNames(def, h.params)]);
        if ((def.live ?? []).length > 0) expect(h.instance.setParam).toBeTypeOf("function");
        h.instance.dispose?.();
      }
    });

    test("one frame of N events = N frames of one event; after reset the output repeats", async () => {
      for (const s of setups) {
        if (s.inputs.length === 0) continue; // sources paced by their own timer: nothing to batch
        const events = makeEvents(s);
        const one = await harness(def, s);
        feedOneByOne(one, s, events);
        const expected = snapshot(one);
        // The comparison means something only if the block produced something.
        const produced = Object.values(expected).reduce(
          (n, x) => n + (Array.isArray(x) ? x.length : x.t.length),
          0,
        );
        if (!s.silent) expect(produced, JSON.stringify(s.params)).toBeGreaterThan(0);

        const grouped = await harness(def, s);
        feedGrouped(grouped, s, events);
        expect(snapshot(grouped), JSON.stringify(s.params)).toEqual(expected);

        clearAll(one);
        one.instance.reset?.();
        feedOneByOne(one, s, events);
        expect(snapshot(one), `after reset, ${JSON.stringify(s.params)}`).toEqual(expected);
        one.instance.dispose?.();
        grouped.instance.dispose?.();
      }
    });

    test("dispose() twice is harmless, before and after start", async () => {
      for (const s of setups) {
        const h = await BlockHarness.create(def, s.params, {
          inputs: s.inputs,
          now: 0,
          ...(s.resources ? { resources: s.resources } : {}),
        });
        expect(() => h.instance.dispose?.()).not.toThrow();
        expect(() => h.instance.dispose?.()).not.toThrow();
        const started = await harness(def, s);
        if (s.inputs.length > 0) feedOneByOne(started, s, makeEvents(s).slice(0, 5));
        started.instance.stop?.();
        expect(() => started.instance.dispose?.()).not.toThrow();
        expect(() => started.instance.dispose?.()).not.toThrow();
      }
    });

    test("garbage params are refused by zod, the positional form or a BlockConfigError — never an internal error", async () => {
      expect(setups.length, `${type} has no setup in SETUPS`).toBeGreaterThan(0);
      const s = setups[0]!;
      await fc.assert(
        fc.asyncProperty(paramsArbitrary(def, s), async (params) => {
          const failures = (await tryGarbage(def, s, params, CATALOG)).filter(
            (f) => !isKnown(s, describeFailure(params, f)),
          );
          if (failures.length > 0) {
            throw new Error(failures.map((f) => `${f.stage}: ${f.error}`).join("\n"));
          }
        }),
        { numRuns: 100, seed: 20261123 },
      );
    }, 60_000);

    test("each number param at the extremes (0, −1, 1e15, NaN, ±∞, …) is refused or works", async () => {
      expect(setups.length, `${type} has no setup in SETUPS`).toBeGreaterThan(0);
      const s = setups[0]!;
      const found: string[] = [];
      for (const params of extremeVariants(def, s)) {
        for (const f of await tryGarbage(def, s, params, CATALOG))
          found.push(describeFailure(params, f));
      }
      expect(found.filter((f) => !isKnown(s, f))).toEqual([]);
      for (const k of s.known ?? []) {
        expect(
          found.some((f) => k.pattern.test(f)),
          `known issue no longer occurs, remove it from SETUPS.${type}.known: ${k.reason}`,
        ).toBe(true);
      }
    }, 60_000);

    test("mosaic test-block's checks (runBlockContract) pass with every setup", async () => {
      expect(setups.length, `${type} has no setup in SETUPS`).toBeGreaterThan(0);
      const failed: string[] = [];
      for (const [i, s] of setups.entries()) {
        const results = await runBlockContract(
          def,
          contractSetup(s),
          s.resources ?? noFiles,
          CATALOG,
          undefined,
          { garbageRuns: PROGRAM_GARBAGE_RUNS },
        );
        expect(results.map((r) => r.name)).toEqual([...CHECK_NAMES]);
        for (const r of results) {
          // A known internal error (see Setup.known) fails the program's garbage check too.
          const known = (s.known ?? []).some((k) => k.pattern.test(r.detail));
          if (!r.ok && !(r.name === "garbage params" && known)) {
            failed.push(`${type}, setup ${i + 1} of ${setups.length}: ${r.name}: ${r.detail}`);
          }
        }
      }
      expect(failed).toEqual([]);
    }, 120_000);
  });
});
