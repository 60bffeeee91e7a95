import { z } from "zod";
import { defineBlock, vectorShape } from "../../engine";
import { TextThrottle } from "../shared/text";
import { InletLink } from "./inlet-link";
import { resolveParams } from "./lsl-inlet";
import { lslBridge, streamPredicate } from "./lsl-common";
import { MAX_ITEMS } from "../shared/limits";

const params = z.strictObject({
  ...resolveParams,
  Type: resolveParams.Type.default("Markers"),
  Labels: z
    .array(z.string().max(200))
    .max(MAX_ITEMS)
    .default([])
    .describe(
      "String markers: the value emitted for marker Labels[k] is k; others are read as numbers, NaN when they are not (counted)",
    ),
});
type Params = z.output<typeof params>;

/** The value of a string marker: its index in `labels`, else the number it spells, else NaN. */
export function markerValue(text: string, labels: readonly string[]): number {
  const k = labels.indexOf(text);
  if (k >= 0) return k;
  const t = text.trim();
  return t === "" ? Number.NaN : Number(t);
}

export const LslMarkerInlet = defineBlock({
  type: "LslMarkerInlet",
  category: "Communication",
  summary: "Reads a Lab Streaming Layer marker stream (string or numeric) as [1, 1] events.",
  help:
    "Receives markers from another program (a PsychoPy or OpenViBE experiment, LabRecorder's " +
    "remote control, another MOSAIC's LslMarkers): it resolves a one-channel stream as LslInlet " +
    "does (by default any stream of `Type` Markers; narrow it with `Name` or a `Predicate`) and " +
    "emits one [1, 1] event per marker at the marker's own time on the pipeline clock. A string " +
    "marker becomes its index in `Labels`, or the number it spells; anything else becomes NaN " +
    "and is counted. Numeric marker streams (int32 codes) give their value. The status shows " +
    "markers received, the last one, the clock offset and losses. Unavailable in the browser " +
    "build (the status says so).",
  params,
  inputs: { min: 0, max: 0 },
  views: ["label"],
  panel: "The last marker received, markers received and the stream found.",
  create(ctx, p: Params) {
    const predicate = streamPredicate(p);
    const out = ctx.output(vectorShape(1));
    const throttle = new TextThrottle(0.25);
    let last = "";
    let unmapped = 0;
    const link = new InletLink(ctx, {
      predicate,
      channels: 1,
      acceptStrings: true,
      bufferS: p.BufferSeconds,
      recover: p.Recover,
      onSamples(n, values, strings, times) {
        const f = out.frame(n);
        for (let i = 0; i < n; i++) {
          f.t[i] = times[i]!;
          if (strings) {
            last = strings[i]!;
            const v = markerValue(last, p.Labels);
            if (Number.isNaN(v)) unmapped++;
            f.v[i] = v;
          } else {
            f.v[i] = values[i]!;
            last = String(values[i]);
          }
        }
        out.emit(f);
      },
    });
    const describe = (): void => {
      let s = link.text();
      if (link.samples > 0) s += `, last '${last}'`;
      if (unmapped > 0) s += `, ${unmapped} not a label or number (NaN)`;
      ctx.setText(s);
    };
    // Every due tick in one call (a stall is not a skipped tick: the block is not behind).
    const timer = ctx.every(p.PollRate, (times, n) => {
      const now = times[n - 1]!;
      link.poll(now);
      if (throttle.due(now)) describe();
    });
    return {
      start() {
        const lsl = lslBridge(ctx);
        if (!lsl) return;
        if (!link.start(lsl)) {
          ctx.error(`LSL marker inlet: ${link.failure}`);
          ctx.setText(link.failure);
          return;
        }
        describe();
        timer.start();
      },
      stop() {
        timer.stop();
        link.close();
        describe();
      },
      dispose() {
        link.close();
      },
    };
  },
});
