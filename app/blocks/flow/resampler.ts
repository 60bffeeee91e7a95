import { z } from "zod";
import { BlockConfigError, defineBlock } from "../../engine";
import { inputName, signalInput } from "../shared/inputs";

export const Resampler = defineBlock({
  type: "Resampler",
  category: "Flow control",
  summary: "Sample-and-hold: on every tick of its timer, emits the latest value of its signal.",
  help:
    "Changes the rate of a stream with a sample-and-hold (paper Table 3): it has two inputs, a " +
    "signal and a timer, in either order. On every timer tick it emits the signal's most recent " +
    "value, stamped with the tick's time; ticks before the signal's first value emit nothing. " +
    "With `Mode: mean` it emits instead the mean of the signal values received since the " +
    "previous tick (an anti-aliasing average when downsampling), and holds the latest value when " +
    "none arrived. Its desired rate is the timer's.",
  params: z.strictObject({
    Mode: z
      .enum(["hold", "mean"])
      .default("hold")
      .describe(
        "hold: the latest signal value; mean: the mean of the values received since the " +
          "previous tick (the latest value when none arrived)",
      ),
  }),
  legacyParams: () => ({}),
  legacyForm: "no params: `{ Type: Resampler, Inputs: [Slow, LowPass] }`",
  inputs: { min: 2, max: 2, labels: ["signal", "timer"] },
  views: ["scope"],
  panel: "Scope of the resampled signal.",
  create(ctx, p) {
    const timers = ctx.inputs.filter((i) => i.isTimer);
    if (timers.length !== 1) {
      const names = ctx.inputs.map(inputName).join(" and ");
      throw new BlockConfigError(
        timers.length === 0
          ? `neither of its inputs ${names} is a timer; Resampler needs one signal and one timer ` +
              "(ScheduledTimer or DecimatorTimer) that sets the output rate"
          : `both of its inputs ${names} are timers; Resampler needs one signal and one timer`,
      );
    }
    const timerPort = timers[0]!.index;
    const signalPort = 1 - timerPort;
    const sig = signalInput(ctx, signalPort);
    const size = sig.size;
    if (ctx.declaredRate === undefined) ctx.setDesiredRate(timers[0]!.rate);
    const out = ctx.output(sig.shape);
    const mean = p.Mode === "mean";
    const latest = new Float64Array(size);
    const sum = new Float64Array(size);
    let count = 0;
    let seen = false;
    const waiting = `waiting for ${sig.info.source}`;
    ctx.setText(waiting);
    return {
      process(f, port) {
        const n = f.n;
        if (port === signalPort) {
          if (n === 0) return;
          const v = f.v;
          if (mean) {
            for (let e = 0; e < n; e++) {
              const off = e * size;
              for (let k = 0; k < size; k++) sum[k] += v[off + k]!;
            }
            count += n;
          }
          const last = (n - 1) * size;
          for (let k = 0; k < size; k++) latest[k] = v[last + k]!;
          if (!seen) {
            seen = true;
            ctx.setText("");
          }
          return;
        }
        if (!seen || n === 0) return;
        const o = out.frame(n);
        const ov = o.v;
        const ft = f.t;
        for (let e = 0; e < n; e++) {
          o.t[e] = ft[e]!;
          const off = e * size;
          if (e === 0 && count > 0) {
            for (let k = 0; k < size; k++) {
              ov[off + k] = sum[k]! / count;
              sum[k] = 0;
            }
            count = 0;
          } else {
            for (let k = 0; k < size; k++) ov[off + k] = latest[k]!;
          }
        }
        out.emit(o);
      },
      reset() {
        latest.fill(0);
        sum.fill(0);
        count = 0;
        seen = false;
        ctx.setText(waiting);
      },
    };
  },
});
