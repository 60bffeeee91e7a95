import { z } from "zod";
import { BlockConfigError, defineBlock } from "../../engine";
import { inputName, signalInput } from "../shared/inputs";
import { SampleQueue } from "./sample-queue";
import { TickQueue } from "./tick-queue";

export const Resampler = defineBlock({
  type: "Resampler",
  category: "Flow control",
  summary: "Sample-and-hold: on every tick of its timer, emits the latest value of its signal.",
  help:
    "Changes the rate of a stream with a sample-and-hold (paper Table 3): it has two inputs, a " +
    "signal and a timer, in either order. On every timer tick it emits the signal's value at the " +
    "tick's time — the latest signal event stamped at or before the tick — stamped with the " +
    "tick's time; ticks before the signal's first value emit nothing. A tick waits for the " +
    "signal events of its own time that the same step is still delivering (so the result does " +
    "not depend on delivery order or on how events are batched), never longer. With " +
    "`Mode: mean` it emits instead the mean of the signal values stamped since the previous " +
    "tick (an anti-aliasing average when downsampling), and holds the latest value when none " +
    "arrived. Its desired rate is the timer's.",
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
    const queue = new SampleQueue(size);
    const ticks = new TickQueue();
    const waiting = `waiting for ${sig.info.source}`;
    ctx.setText(waiting);

    /** Emits the pending ticks stamped at or before `until` (all of them when Infinity). */
    const emitTicks = (until: number): void => {
      const m = ticks.countUntil(until);
      if (m === 0) return;
      const o = out.frame(m);
      const ov = o.v;
      let j = 0;
      for (let e = 0; e < m; e++) {
        const t = ticks.shift();
        queue.consumeUntil(t);
        if (!queue.holding) continue;
        o.t[j] = t;
        if (mean) queue.takeMean(ov, j * size);
        else ov.set(queue.held, j * size);
        j++;
      }
      o.n = j;
      out.emit(o);
    };

    return {
      process(f, port) {
        const n = f.n;
        if (n === 0) return;
        if (port === signalPort) {
          if (queue.length === 0 && !queue.holding) ctx.setText("");
          queue.push(f.t, f.v, n);
          // Every event up to the newest has arrived (events come in order): those ticks can go.
          emitTicks(queue.newest);
          return;
        }
        ticks.push(f.t, n);
        emitTicks(queue.length > 0 ? queue.newest : -Infinity);
      },
      flush() {
        // The step delivered everything it had: what is still waiting goes out now.
        emitTicks(Infinity);
      },
      reset() {
        queue.clear();
        ticks.clear();
        ctx.setText(waiting);
      },
    };
  },
});
