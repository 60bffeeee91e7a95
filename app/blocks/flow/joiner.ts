import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  legacyPair,
  LegacyParamsError,
  vectorShape,
  type BlockContext,
  type Frame,
  type InputInfo,
  type OutputPort,
} from "../../engine";
import { findInput, inputName, vectorInput } from "../shared/inputs";

export const Joiner = defineBlock({
  type: "Joiner",
  category: "Flow control",
  summary: "Concatenates the latest values of its inputs into one vector, once per trigger event.",
  help:
    "Combines several vector streams into one (paper Table 3). The output is the concatenation, " +
    "in the order of `Inputs`, of the most recent value of every input that is not a timer. It " +
    "emits one vector per event of its Trigger input, stamped with that event's time, once every " +
    "data input has produced at least one value (until then its status says which ones it is " +
    "waiting for). When the trigger is a data input, its own slot holds the triggering event's " +
    "value. Trigger defaults to the first timer input, or to the first input when there is no " +
    "timer; its desired rate is the trigger's. Matrix inputs are not accepted (use a Projector or " +
    "a window feature first).",
  params: z.strictObject({
    Trigger: z
      .string()
      .min(1)
      .optional()
      .describe(
        "The input (block name as written in Inputs) whose events make the Joiner emit; default " +
          "the first timer input, else the first input",
      ),
  }),
  legacyParams(args) {
    const out: Record<string, string> = {};
    for (const a of args) {
      const { key, value } = legacyPair(a);
      if (key === "timerBlockName") {
        if (value === "")
          throw new LegacyParamsError("timerBlockName has no block name", "Trigger");
        out.Trigger = value;
      } else if (key !== "") {
        throw new LegacyParamsError(`unknown argument '${a}' (expected timerBlockName:<block>)`);
      }
    }
    return out;
  },
  legacyForm: "[timerBlockName:Timer]: the block whose events trigger an output",
  inputs: { min: 2, max: Infinity },
  views: ["scope", "spider"],
  panel: "Scope of the joined vector.",
  create(ctx, p) {
    const trigger = triggerInput(ctx, p.Trigger);
    const triggerPort = trigger.index;
    const { offsets, widths, width, data } = joinLayout(ctx);
    if (ctx.declaredRate === undefined) ctx.setDesiredRate(trigger.rate);
    const out = ctx.output(vectorShape(width));
    const joined = new Float64Array(width);
    const seen = new Uint8Array(ctx.inputs.length);
    let missing = data.length;
    describeWaiting(ctx, data, seen);
    return {
      process(f, port) {
        const n = f.n;
        if (n === 0) return;
        const off = offsets[port]!;
        const w = widths[port]!;
        if (off >= 0 && seen[port] === 0) {
          seen[port] = 1;
          missing--;
          describeWaiting(ctx, data, seen);
        }
        // Not the trigger, or not every data input has a value yet: keep the latest value only.
        if (port !== triggerPort || missing > 0) {
          if (off >= 0) copyEvent(joined, off, f.v, n - 1, w);
          return;
        }
        emitJoined(out, f, joined, off, w);
      },
      reset() {
        joined.fill(0);
        seen.fill(0);
        missing = data.length;
        describeWaiting(ctx, data, seen);
      },
    };
  },
});

/** The Trigger input: the one named, else the first timer input, else the first input. */
function triggerInput(ctx: BlockContext, name: string | undefined): InputInfo {
  return name !== undefined
    ? findInput(ctx, name, "Trigger")
    : (ctx.inputs.find((i) => i.isTimer) ?? ctx.inputs[0]!);
}

/** Where each input's latest value sits in the joined vector. */
interface JoinLayout {
  /** Offset of each data input in the output; -1 for timers. */
  offsets: Int32Array;
  /** Values per event of each data input; 0 for timers. */
  widths: Int32Array;
  /** Width of the joined vector. */
  width: number;
  /** Positions of the data inputs (not timers), in the order of Inputs. */
  data: number[];
}

/** The data inputs laid end to end (each must be a vector); at least one must not be a timer. */
function joinLayout(ctx: BlockContext): JoinLayout {
  const inputs = ctx.inputs;
  const offsets = new Int32Array(inputs.length).fill(-1);
  const widths = new Int32Array(inputs.length);
  let width = 0;
  const data: number[] = [];
  for (const info of inputs) {
    if (info.isTimer) continue;
    const s = vectorInput(ctx, info.index);
    offsets[info.index] = width;
    widths[info.index] = s.size;
    width += s.size;
    data.push(info.index);
  }
  if (data.length === 0) {
    throw new BlockConfigError(
      `all of its inputs (${inputs.map(inputName).join(", ")}) are timers; Joiner needs at least ` +
        "one data input",
    );
  }
  return { offsets, widths, width, data };
}

/** The status: the data inputs that have not produced a value yet (none: empty). */
function describeWaiting(ctx: BlockContext, data: readonly number[], seen: Uint8Array): void {
  const waiting = data.filter((i) => seen[i] === 0).map((i) => ctx.inputs[i]!.source);
  ctx.setText(waiting.length > 0 ? `waiting for ${waiting.join(", ")}` : "");
}

/** Copies the value of event `e` (`w` values per event in `v`) into `joined` at `off`. */
function copyEvent(joined: Float64Array, off: number, v: Float64Array, e: number, w: number): void {
  const src = e * w;
  for (let k = 0; k < w; k++) joined[off + k] = v[src + k]!;
}

/**
 * Emits the joined vector once per event of the trigger frame `f`, stamped with its time; a data
 * trigger (`off` ≥ 0, `w` values) first puts each event's own value in its slot.
 */
function emitJoined(out: OutputPort, f: Frame, joined: Float64Array, off: number, w: number): void {
  const n = f.n;
  const width = joined.length;
  const o = out.frame(n);
  const ov = o.v;
  const ft = f.t;
  const v = f.v;
  for (let e = 0; e < n; e++) {
    o.t[e] = ft[e]!;
    if (off >= 0) copyEvent(joined, off, v, e, w);
    const dst = e * width;
    for (let k = 0; k < width; k++) ov[dst + k] = joined[k]!;
  }
  out.emit(o);
}
