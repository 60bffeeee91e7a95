import { z } from "zod";
import { BlockConfigError, defineBlock, formatShape, type Frame } from "../../engine";
import { formatCount, TextThrottle } from "../shared/text";
import {
  bufferParam,
  defaultSourceId,
  describeStream,
  nameParam,
  OutletLink,
  toIntegerFormat,
} from "./lsl-common";
import { MAX_CHANNELS } from "../shared/limits";

const params = z.strictObject({
  Name: nameParam(
    "The stream's name as inlets and LabRecorder see it (default: this block's name)",
  ),
  Type: z
    .string()
    .max(200)
    .default("EMG")
    .describe("The stream's content type (LSL's conventions: EEG, EMG, Gaze, Mocap, …)"),
  Format: z
    .enum(["float32", "double64", "int32", "int16", "string"])
    .default("float32")
    .describe(
      "How values travel: float32 (LSL's usual), double64 (exact), int32/int16 (rounded, out-of-range values clamped and counted), string (each value as text)",
    ),
  ChannelLabels: z
    .array(z.string().max(200))
    .max(MAX_CHANNELS)
    .optional()
    .describe("One label per channel (the input's values in row-major order); default Ch1, Ch2, …"),
  NominalRate: z
    .number()
    .min(0)
    .optional()
    .describe("The stream's nominal rate in Hz (0: irregular); default the input's rate"),
  SourceId: z
    .string()
    .max(200)
    .optional()
    .describe(
      "A unique id of the source, so that inlets reconnect to it after a restart; default mosaic:<block>:<Name>",
    ),
  BufferSeconds: bufferParam,
});
type Params = z.output<typeof params>;

export const LslOutlet = defineBlock({
  type: "LslOutlet",
  category: "Communication",
  summary: "Publishes its input as a Lab Streaming Layer stream (one LSL chunk per frame).",
  help:
    "Makes a block's output visible to every Lab Streaming Layer program on the network " +
    "(LabRecorder, OpenViBE, BCILAB, pylsl, another MOSAIC): an outlet with `Name`, `Type`, one " +
    "channel per input value (row-major for a matrix) with `ChannelLabels` in its description, " +
    "the nominal rate of the input (or `NominalRate`), the value `Format` and a `SourceId` that " +
    "stays the same across runs so that inlets recover the stream after a restart. Each frame " +
    "goes out as one chunk, each event with its own timestamp mapped onto LSL's clock " +
    "(`lsl_local_clock`: the offset between the two clocks is measured at start with bracketed " +
    "readings and checked every 5 s). Integer formats round and clamp (counted). Uses liblsl " +
    "(the pylsl wheel's copy, or `MOSAIC_LIBLSL`); discovery follows liblsl's configuration " +
    "(`LSLAPICFG`, `lsl_api.cfg`). Unavailable in the browser build: the status says so. " +
    "Under the virtual clock, timestamps are the virtual times shifted to LSL's clock at start.",
  params,
  inputs: { min: 1, max: 1, labels: ["signal"] },
  outputs: [],
  panel: "The stream's name, format and rate, samples and chunks sent, whether an inlet listens.",
  create(ctx, p: Params) {
    const input = ctx.inputs[0]!;
    if (!input.shape) {
      throw new BlockConfigError("the input's shape is unknown (a feedback cycle?)", "Inputs");
    }
    const channels = input.shape.rows * input.shape.cols;
    if (channels === 0) {
      throw new BlockConfigError(
        `input ${input.source} carries no values (${formatShape(input.shape)}): use LslMarkers for events`,
        "Inputs",
      );
    }
    const labels = p.ChannelLabels ?? Array.from({ length: channels }, (_, i) => `Ch${i + 1}`);
    if (labels.length !== channels) {
      throw new BlockConfigError(
        `${labels.length} ChannelLabels for ${channels} channels (input ${formatShape(input.shape)})`,
        "ChannelLabels",
      );
    }
    const name = p.Name || ctx.name;
    const info = {
      name,
      type: p.Type,
      channels,
      rate: p.NominalRate ?? input.rate,
      format: p.Format,
      sourceId: p.SourceId || defaultSourceId(ctx, name),
      labels,
    };
    const link = new OutletLink(ctx, info, p.BufferSeconds);
    const throttle = new TextThrottle(0.25);
    let values = new Float64Array(0);
    let times = new Float64Array(0);
    let strings: string[] = [];
    let samples = 0;
    let chunks = 0;
    let clamped = 0;
    let unsent = 0;

    const describe = (): void => {
      if (link.failure !== "") return;
      const parts = [
        `streaming '${name}' (${describeStream(info)})`,
        `${formatCount(samples)} samples in ${formatCount(chunks)} chunks`,
        link.outlet?.haveConsumers() ? "an inlet listens" : "no inlet connected",
      ];
      if (clamped > 0) parts.push(`${formatCount(clamped)} values clamped to ${p.Format}`);
      if (unsent > 0) parts.push(`${formatCount(unsent)} samples not sent (no outlet)`);
      ctx.setText(parts.join(", "));
    };

    const send = (f: Frame): void => {
      const outlet = link.outlet!;
      const n = f.n;
      if (times.length < n) times = new Float64Array(n * 2);
      for (let i = 0; i < n; i++) times[i] = link.clock.toLsl(f.t[i]!);
      const m = n * channels;
      if (p.Format === "string") {
        strings.length = m;
        for (let k = 0; k < m; k++) strings[k] = String(f.v[k]!);
        outlet.pushStrings(strings, times.subarray(0, n));
        return;
      }
      if (p.Format === "int32" || p.Format === "int16") {
        if (values.length < m) values = new Float64Array(m * 2);
        values.set(f.v.subarray(0, m));
        clamped += toIntegerFormat(values, m, p.Format);
        outlet.push(values, n, times);
        return;
      }
      outlet.push(f.v, n, times);
    };

    return {
      start() {
        if (link.open()) describe();
      },
      process(f: Frame) {
        if (f.n === 0) return;
        if (!link.outlet) {
          unsent += f.n;
          return;
        }
        link.check();
        send(f);
        samples += f.n;
        chunks++;
        if (throttle.due(ctx.now())) describe();
      },
      stop() {
        describe();
        link.close();
      },
      reset() {
        samples = 0;
        chunks = 0;
        clamped = 0;
        unsent = 0;
        strings = [];
      },
      dispose() {
        link.close();
      },
    };
  },
});
