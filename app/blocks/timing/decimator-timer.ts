import { z } from "zod";
import { BlockConfigError, defineBlock, EMPTY_SHAPE } from "../../engine";

/** 1st, 2nd, 3rd, 4th, …, 11th, 12th, 13th, …, 21st, 82nd. */
export function ordinal(n: number): string {
  const t = n % 100;
  if (t >= 11 && t <= 13) return `${n}th`;
  return `${n}${["th", "st", "nd", "rd"][n % 10] ?? "th"}`;
}

export const DecimatorTimer = defineBlock({
  type: "DecimatorTimer",
  category: "Timing",
  summary: "Forwards every N-th tick of another timer, N = input rate / DesiredRate.",
  help:
    "Downsamples the pace for parts of a pipeline that run slower (paper III-D), so a whole " +
    "pipeline shares one clock: e.g. a 200 Hz timer and a 25 Hz decimator forward every 8th tick. " +
    "When the input rate is not a multiple of DesiredRate, N is rounded to the nearest integer " +
    "and a warning gives the resulting rate. The first tick is forwarded.",
  params: z.strictObject({}),
  legacyParams: () => ({}),
  legacyForm: "no params: `{ Type: DecimatorTimer, DesiredRate: 25, Inputs: [Timer] }`",
  inputs: { min: 1, max: 1, labels: ["timer"] },
  timer: true,
  views: ["label"],
  panel: "Decimation factor and actual rate.",
  create(ctx) {
    const input = ctx.inputs[0]!;
    if (!input.isTimer) {
      throw new BlockConfigError(
        `its input '${input.source}' must be a timer (ScheduledTimer or DecimatorTimer)`,
      );
    }
    const desired = ctx.declaredRate ?? ctx.desiredRate;
    if (input.rate > 0 && desired > input.rate) {
      throw new BlockConfigError(
        `DesiredRate ${desired} Hz is faster than its input timer's ${input.rate} Hz`,
      );
    }
    const factor = input.rate > 0 ? Math.max(1, Math.round(input.rate / desired)) : 1;
    const effective = input.rate > 0 ? input.rate / factor : desired;
    if (input.rate > 0 && Math.abs(effective - desired) > 1e-9 * desired) {
      ctx.warn(
        `${input.rate} Hz / ${desired} Hz is not a whole number; forwarding every ${ordinal(factor)} tick gives ${effective.toPrecision(6)} Hz`,
      );
    }
    ctx.setDesiredRate(effective);
    ctx.setText(`every ${ordinal(factor)} tick`);
    const out = ctx.output(EMPTY_SHAPE);
    let count = 0;
    return {
      process(f) {
        // Which events of this frame are forwarded depends only on the running count.
        let m = 0;
        for (let i = 0; i < f.n; i++) if ((count + i) % factor === 0) m++;
        if (m > 0) {
          const o = out.frame(m);
          let j = 0;
          for (let i = 0; i < f.n; i++) if ((count + i) % factor === 0) o.t[j++] = f.t[i]!;
          out.emit(o);
        }
        count = (count + f.n) % factor;
      },
      reset() {
        count = 0;
      },
    };
  },
});
