import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  formatShape,
  type BlockContext,
  type BlockInstance,
  type Frame,
  type InputInfo,
  type LslStreamInfo,
  type Shape,
} from "../../engine";
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

/** The input's shape, refused when it is unknown. */
function knownShape(input: InputInfo): Shape {
  if (!input.shape) {
    throw new BlockConfigError("the input's shape is unknown (a feedback cycle?)", "Inputs");
  }
  return input.shape;
}

/** The stream's channel count: the input's values per event, refused when there are none. */
function inputChannels(input: InputInfo, shape: Shape): number {
  const channels = shape.rows * shape.cols;
  if (channels === 0) {
    throw new BlockConfigError(
      `input ${input.source} carries no values (${formatShape(shape)}): use LslMarkers for events`,
      "Inputs",
    );
  }
  return channels;
}

/** The channel labels: `ChannelLabels` (one per channel, else refused) or Ch1, Ch2, …. */
function channelLabels(
  given: readonly string[] | undefined,
  channels: number,
  shape: Shape,
): readonly string[] {
  const labels = given ?? Array.from({ length: channels }, (_, i) => `Ch${i + 1}`);
  if (labels.length !== channels) {
    throw new BlockConfigError(
      `${labels.length} ChannelLabels for ${channels} channels (input ${formatShape(shape)})`,
      "ChannelLabels",
    );
  }
  return labels;
}

/** The stream's metadata as inlets see it. */
function streamInfo(
  ctx: BlockContext,
  p: Params,
  inputRate: number,
  channels: number,
  labels: readonly string[],
): LslStreamInfo & { labels: readonly string[] } {
  const name = p.Name || ctx.name;
  return {
    name,
    type: p.Type,
    channels,
    rate: p.NominalRate ?? inputRate,
    format: p.Format,
    sourceId: p.SourceId || defaultSourceId(ctx, name),
    labels,
  };
}

/** One LslOutlet's run: the outlet, the frames sent as chunks, the counters and the status. */
class OutletRun {
  private readonly link: OutletLink;
  private readonly throttle = new TextThrottle(0.25);
  private values = new Float64Array(0);
  private times = new Float64Array(0);
  private strings: string[] = [];
  private samples = 0;
  private chunks = 0;
  private clamped = 0;
  private unsent = 0;

  constructor(
    private readonly ctx: BlockContext,
    private readonly format: Params["Format"],
    private readonly info: LslStreamInfo,
    bufferS: number,
  ) {
    this.link = new OutletLink(ctx, info, bufferS);
  }

  /** The block's instance (see OutletLink.instance). */
  instance(): BlockInstance {
    return this.link.instance({
      process: (f) => this.process(f),
      describe: () => this.describe(),
      reset: () => this.reset(),
    });
  }

  /** Sends a frame as one chunk and counts it (or counts it unsent while there is no outlet). */
  private process(f: Frame): void {
    if (f.n === 0) return;
    if (!this.link.outlet) {
      this.unsent += f.n;
      return;
    }
    this.link.check();
    this.send(f);
    this.samples += f.n;
    this.chunks++;
    if (this.throttle.due(this.ctx.now())) this.describe();
  }

  /** Pushes the frame's values in the stream's format, with its times on LSL's clock. */
  private send(f: Frame): void {
    const outlet = this.link.outlet!;
    const n = f.n;
    if (this.times.length < n) this.times = new Float64Array(n * 2);
    for (let i = 0; i < n; i++) this.times[i] = this.link.clock.toLsl(f.t[i]!);
    const m = n * this.info.channels;
    if (this.format === "string") {
      this.strings.length = m;
      for (let k = 0; k < m; k++) this.strings[k] = String(f.v[k]!);
      outlet.pushStrings(this.strings, this.times.subarray(0, n));
      return;
    }
    if (this.format === "int32" || this.format === "int16") {
      if (this.values.length < m) this.values = new Float64Array(m * 2);
      this.values.set(f.v.subarray(0, m));
      this.clamped += toIntegerFormat(this.values, m, this.format);
      outlet.push(this.values, n, this.times);
      return;
    }
    outlet.push(f.v, n, this.times);
  }

  /** Shows the stream, what was sent, whether an inlet listens (unless the outlet failed). */
  private describe(): void {
    if (this.link.failure !== "") return;
    const parts = [
      `streaming '${this.info.name}' (${describeStream(this.info)})`,
      `${formatCount(this.samples)} samples in ${formatCount(this.chunks)} chunks`,
      this.link.outlet?.haveConsumers() ? "an inlet listens" : "no inlet connected",
    ];
    if (this.clamped > 0)
      parts.push(`${formatCount(this.clamped)} values clamped to ${this.format}`);
    if (this.unsent > 0) parts.push(`${formatCount(this.unsent)} samples not sent (no outlet)`);
    this.ctx.setText(parts.join(", "));
  }

  /** Clears the counters. */
  private reset(): void {
    this.samples = 0;
    this.chunks = 0;
    this.clamped = 0;
    this.unsent = 0;
    this.strings = [];
  }
}

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
    const shape = knownShape(input);
    const channels = inputChannels(input, shape);
    const labels = channelLabels(p.ChannelLabels, channels, shape);
    const info = streamInfo(ctx, p, input.rate, channels, labels);
    return new OutletRun(ctx, p.Format, info, p.BufferSeconds).instance();
  },
});
