import { z } from "zod";
import {
  defineBlock,
  vectorShape,
  type BlockContext,
  type BlockInstance,
  type OutputPort,
  type TimerHandle,
} from "../../engine";
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
    return new MarkerInletRun(ctx, p, predicate, out).instance();
  },
});

/** One LslMarkerInlet at run time: its inlet, the poll timer, the last marker and the status. */
class MarkerInletRun {
  private readonly throttle = new TextThrottle(0.25);
  private readonly link: InletLink;
  private readonly timer: TimerHandle;
  /** The last marker received, as text. */
  private last = "";
  /** String markers that were neither a label nor a number (emitted as NaN). */
  private unmapped = 0;

  constructor(
    private readonly ctx: BlockContext,
    private readonly p: Params,
    predicate: string,
    private readonly out: OutputPort,
  ) {
    this.link = new InletLink(ctx, {
      predicate,
      channels: 1,
      acceptStrings: true,
      bufferS: p.BufferSeconds,
      recover: p.Recover,
      onSamples: this.onSamples,
    });
    // Every due tick in one call (a stall is not a skipped tick: the block is not behind).
    this.timer = ctx.every(p.PollRate, (times, n) => this.poll(times[n - 1]!));
  }

  /** The block instance the engine drives. */
  instance(): BlockInstance {
    return {
      start: () => this.start(),
      stop: () => {
        this.timer.stop();
        this.link.close();
        this.describe();
      },
      dispose: () => {
        this.link.close();
      },
    };
  }

  /** Starts resolving the stream and polling (or says why LSL cannot be used). */
  private start(): void {
    const { ctx, link } = this;
    const lsl = lslBridge(ctx);
    if (!lsl) return;
    if (!link.start(lsl)) {
      ctx.error(`LSL marker inlet: ${link.failure}`);
      ctx.setText(link.failure);
      return;
    }
    this.describe();
    this.timer.start();
  }

  /** Emits the markers pulled as one frame of [1, 1] events (bound: the link's callback). */
  private readonly onSamples = (
    n: number,
    values: Float64Array,
    strings: readonly string[] | undefined,
    times: Float64Array,
  ): void => {
    const f = this.out.frame(n);
    for (let i = 0; i < n; i++) {
      f.t[i] = times[i]!;
      if (strings) {
        this.last = strings[i]!;
        const v = markerValue(this.last, this.p.Labels);
        if (Number.isNaN(v)) this.unmapped++;
        f.v[i] = v;
      } else {
        f.v[i] = values[i]!;
        this.last = String(values[i]);
      }
    }
    this.out.emit(f);
  };

  /** Pulls what arrived by `now` and refreshes the status now and then. */
  private poll(now: number): void {
    this.link.poll(now);
    if (this.throttle.due(now)) this.describe();
  }

  /** The status: the link's, the last marker and the markers read as NaN. */
  private describe(): void {
    let s = this.link.text();
    if (this.link.samples > 0) s += `, last '${this.last}'`;
    if (this.unmapped > 0) s += `, ${this.unmapped} not a label or number (NaN)`;
    this.ctx.setText(s);
  }
}
