import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  legacyPair,
  LegacyParamsError,
  vectorShape,
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
    const inputs = ctx.inputs;
    const trigger =
      p.Trigger !== undefined
        ? findInput(ctx, p.Trigger, "Trigger")
        : (inputs.find((i) => i.isTimer) ?? inputs[0]!);
    const triggerPort = trigger.index;
    const nIn = inputs.length;
    // Offset of each data input in the output; -1 for timers.
    const offsets = new Int32Array(nIn).fill(-1);
    const widths = new Int32Array(nIn);
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
    if (ctx.declaredRate === undefined) ctx.setDesiredRate(trigger.rate);
    const out = ctx.output(vectorShape(width));
    const joined = new Float64Array(width);
    const seen = new Uint8Array(nIn);
    let missing = data.length;
    const describe = () => {
      const waiting = data.filter((i) => seen[i] === 0).map((i) => inputs[i]!.source);
      ctx.setText(waiting.length > 0 ? `waiting for ${waiting.join(", ")}` : "");
    };
    describe();
    return {
      process(f, port) {
        const n = f.n;
        if (n === 0) return;
        const off = offsets[port]!;
        const w = widths[port]!;
        const v = f.v;
        if (off >= 0 && seen[port] === 0) {
          seen[port] = 1;
          missing--;
          describe();
        }
        if (port !== triggerPort) {
          if (off >= 0) {
            const last = (n - 1) * w;
            for (let k = 0; k < w; k++) joined[off + k] = v[last + k]!;
          }
          return;
        }
        if (missing > 0) {
          if (off >= 0) {
            const last = (n - 1) * w;
            for (let k = 0; k < w; k++) joined[off + k] = v[last + k]!;
          }
          return;
        }
        const o = out.frame(n);
        const ov = o.v;
        const ft = f.t;
        for (let e = 0; e < n; e++) {
          o.t[e] = ft[e]!;
          if (off >= 0) {
            const src = e * w;
            for (let k = 0; k < w; k++) joined[off + k] = v[src + k]!;
          }
          const dst = e * width;
          for (let k = 0; k < width; k++) ov[dst + k] = joined[k]!;
        }
        out.emit(o);
      },
      reset() {
        joined.fill(0);
        seen.fill(0);
        missing = data.length;
        describe();
      },
    };
  },
});
