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
} from "../../engine";
import { formatCount, TextThrottle } from "../shared/text";
import { bufferParam, defaultSourceId, nameParam, OutletLink } from "./lsl-common";
import { MAX_ITEMS } from "../shared/limits";

const params = z.strictObject({
  Name: nameParam("The marker stream's name (default: this block's name)"),
  Type: z
    .string()
    .max(200)
    .default("Markers")
    .describe("The stream's content type (LSL's convention: Markers)"),
  Format: z
    .enum(["string", "int32"])
    .default("string")
    .describe("string markers (LabRecorder, most tools) or int32 codes (OpenViBE stimulations)"),
  Channel: z
    .number()
    .int()
    .min(0)
    .default(0)
    .describe("Which value of each input event is the marker (0: the first)"),
  Labels: z
    .array(z.string().max(200))
    .max(MAX_ITEMS)
    .default([])
    .describe(
      "string: the marker sent for value k is Labels[k] (a Trigger's or Stimulus's label index); values without a label go as their number",
    ),
  NanMarker: z
    .string()
    .max(200)
    .default("stop")
    .describe("string: the marker sent for NaN (a Trigger's stop)"),
  NanCode: z.number().int().default(-1).describe("int32: the code sent for NaN"),
  SkipNaN: z.boolean().default(false).describe("Send nothing for NaN values"),
  SourceId: z
    .string()
    .max(200)
    .optional()
    .describe("A unique id of the source (default mosaic:<block>:<Name>)"),
  BufferSeconds: bufferParam,
});
type Params = z.output<typeof params>;

/** The int32 code for `v`: rounded, clamped to int32 (counted by the caller when changed). */
export function markerCode(v: number): number {
  const r = Math.round(v);
  return Math.min(2147483647, Math.max(-2147483648, r));
}

/** The string marker for `v`: its label when it is a label's index, else the number. */
export function markerText(v: number, labels: readonly string[]): string {
  if (Number.isInteger(v) && v >= 0 && v < labels.length) return labels[v]!;
  return String(v);
}

/** Refuses a `Channel` that is not a value of the input (when its shape is known). */
function checkChannel(input: InputInfo, channel: number): void {
  const width = input.shape ? input.shape.rows * input.shape.cols : 0;
  if (input.shape && channel >= width) {
    throw new BlockConfigError(
      `Channel ${channel} is not a value of input ${input.source} (${formatShape(input.shape)})`,
      "Channel",
    );
  }
}

/** The marker stream's metadata: one irregular channel. */
function markerStreamInfo(ctx: BlockContext, p: Params, name: string): LslStreamInfo {
  return {
    name,
    type: p.Type,
    channels: 1,
    rate: 0,
    format: p.Format,
    sourceId: p.SourceId || defaultSourceId(ctx, name),
  };
}

/** One LslMarkers' run: the outlet, the markers sent as chunks, the counters and the status. */
class MarkersRun {
  private readonly link: OutletLink;
  private readonly throttle = new TextThrottle(0.25);
  private codes = new Float64Array(0);
  private times = new Float64Array(0);
  private readonly texts: string[] = [];
  private sent = 0;
  private last = "";
  private clamped = 0;
  private unsent = 0;

  constructor(
    private readonly ctx: BlockContext,
    private readonly p: Params,
    private readonly name: string,
    info: LslStreamInfo,
  ) {
    this.link = new OutletLink(ctx, info, p.BufferSeconds);
  }

  /** The block's instance (see OutletLink.instance). */
  instance(): BlockInstance {
    return this.link.instance({
      process: (f) => this.process(f),
      describe: () => this.describe(),
      reset: () => this.reset(),
    });
  }

  /** Sends a frame's markers as one chunk (or counts them unsent while there is no outlet). */
  private process(f: Frame): void {
    if (f.n === 0) return;
    if (!this.link.outlet) {
      this.unsent += f.n;
      return;
    }
    this.link.check();
    this.sent += this.send(f);
    if (this.throttle.due(this.ctx.now())) this.describe();
  }

  /** Pushes the frame's markers with their times on LSL's clock; returns how many were sent. */
  private send(f: Frame): number {
    const p = this.p;
    const outlet = this.link.outlet!;
    if (this.times.length < f.n) {
      this.times = new Float64Array(f.n * 2);
      this.codes = new Float64Array(f.n * 2);
    }
    this.texts.length = 0;
    let k = 0;
    for (let i = 0; i < f.n; i++) {
      const v = f.v[i * f.stride + p.Channel]!;
      if (Number.isNaN(v) && p.SkipNaN) continue;
      this.times[k] = this.link.clock.toLsl(f.t[i]!);
      if (p.Format === "string") {
        this.last = Number.isNaN(v) ? p.NanMarker : markerText(v, p.Labels);
        this.texts.push(this.last);
      } else {
        const c = Number.isNaN(v) ? p.NanCode : markerCode(v);
        if (!Number.isNaN(v) && c !== Math.round(v)) this.clamped++;
        this.codes[k] = c;
        this.last = String(c);
      }
      k++;
    }
    if (k === 0) return 0;
    if (p.Format === "string") outlet.pushStrings(this.texts, this.times.subarray(0, k));
    else outlet.push(this.codes, k, this.times);
    return k;
  }

  /** Shows the markers sent, the last one and what was clamped or not sent (unless it failed). */
  private describe(): void {
    if (this.link.failure !== "") return;
    const tail = this.sent > 0 ? `, last '${this.last}'` : "";
    const extra = [
      this.clamped > 0 ? `${this.clamped} clamped to int32` : "",
      this.unsent > 0 ? `${this.unsent} not sent (no outlet)` : "",
    ].filter((s) => s !== "");
    this.ctx.setText(
      `markers '${this.name}' (${this.p.Format}): ${formatCount(this.sent)} sent${tail}` +
        (extra.length > 0 ? `, ${extra.join(", ")}` : ""),
    );
  }

  /** Clears the counters and the last marker. */
  private reset(): void {
    this.sent = 0;
    this.clamped = 0;
    this.unsent = 0;
    this.last = "";
  }
}

export const LslMarkers = defineBlock({
  type: "LslMarkers",
  category: "Communication",
  summary: "Sends its input's events as a Lab Streaming Layer marker stream (string or int32).",
  help:
    "Publishes events (a Trigger's `label`, a Stimulus's `phase` or `cue`, a TAC's `trial`, any " +
    "event stream) as an irregular one-channel LSL marker stream, one marker per event at the " +
    "event's own time mapped onto LSL's clock, so that LabRecorder records them beside the data " +
    "and OpenViBE reads them as stimulations. The marker is value `Channel` of the event: with " +
    "`Format: string` the label `Labels[value]` (or the number as text), with `int32` the value " +
    "rounded; NaN (a Trigger's stop) sends `NanMarker` / `NanCode` unless `SkipNaN`. Each frame " +
    "goes out as one chunk. Unavailable in the browser build: the status says so.",
  params,
  inputs: { min: 1, max: 1, labels: ["events"] },
  outputs: [],
  panel: "The marker stream's name, markers sent and the last one.",
  create(ctx, p: Params) {
    checkChannel(ctx.inputs[0]!, p.Channel);
    const name = p.Name || ctx.name;
    const info = markerStreamInfo(ctx, p, name);
    return new MarkersRun(ctx, p, name, info).instance();
  },
});
