import { z } from "zod";
import { BlockConfigError, defineBlock, formatShape, type Frame } from "../../engine";
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
    const input = ctx.inputs[0]!;
    const width = input.shape ? input.shape.rows * input.shape.cols : 0;
    if (input.shape && p.Channel >= width) {
      throw new BlockConfigError(
        `Channel ${p.Channel} is not a value of input ${input.source} (${formatShape(input.shape)})`,
        "Channel",
      );
    }
    const name = p.Name || ctx.name;
    const link = new OutletLink(
      ctx,
      {
        name,
        type: p.Type,
        channels: 1,
        rate: 0,
        format: p.Format,
        sourceId: p.SourceId || defaultSourceId(ctx, name),
      },
      p.BufferSeconds,
    );
    const throttle = new TextThrottle(0.25);
    let codes = new Float64Array(0);
    let times = new Float64Array(0);
    const texts: string[] = [];
    let sent = 0;
    let last = "";
    let clamped = 0;
    let unsent = 0;

    const describe = (): void => {
      if (link.failure !== "") return;
      const tail = sent > 0 ? `, last '${last}'` : "";
      const extra = [
        clamped > 0 ? `${clamped} clamped to int32` : "",
        unsent > 0 ? `${unsent} not sent (no outlet)` : "",
      ].filter((s) => s !== "");
      ctx.setText(
        `markers '${name}' (${p.Format}): ${formatCount(sent)} sent${tail}` +
          (extra.length > 0 ? `, ${extra.join(", ")}` : ""),
      );
    };

    const send = (f: Frame): number => {
      const outlet = link.outlet!;
      if (times.length < f.n) {
        times = new Float64Array(f.n * 2);
        codes = new Float64Array(f.n * 2);
      }
      texts.length = 0;
      let k = 0;
      for (let i = 0; i < f.n; i++) {
        const v = f.v[i * f.stride + p.Channel]!;
        if (Number.isNaN(v) && p.SkipNaN) continue;
        times[k] = link.clock.toLsl(f.t[i]!);
        if (p.Format === "string") {
          last = Number.isNaN(v) ? p.NanMarker : markerText(v, p.Labels);
          texts.push(last);
        } else {
          const c = Number.isNaN(v) ? p.NanCode : markerCode(v);
          if (!Number.isNaN(v) && c !== Math.round(v)) clamped++;
          codes[k] = c;
          last = String(c);
        }
        k++;
      }
      if (k === 0) return 0;
      if (p.Format === "string") outlet.pushStrings(texts, times.subarray(0, k));
      else outlet.push(codes, k, times);
      return k;
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
        sent += send(f);
        if (throttle.due(ctx.now())) describe();
      },
      stop() {
        describe();
        link.close();
      },
      reset() {
        sent = 0;
        clamped = 0;
        unsent = 0;
        last = "";
      },
      dispose() {
        link.close();
      },
    };
  },
});
