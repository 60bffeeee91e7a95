import { z } from "zod";
import { defineBlock } from "../../engine";
import { signalInput } from "../shared/inputs";

export const Busy = defineBlock({
  type: "Busy",
  category: "Testing",
  summary: "Passes its input through unchanged, spinning the CPU for a while on some calls.",
  help:
    "A deliberately slow block for demonstrating and testing the timing status (paper III-B): it " +
    "forwards every frame unchanged, but on every `Every`-th call it first busy-waits for " +
    "`Milliseconds` (measured with the monotonic clock). A spin longer than one period of its " +
    "desired rate marks it stumbling (magenta); spinning on every call for longer than a period " +
    "makes everything after it lag (red). Both params can be changed while running.",
  params: z.strictObject({
    Milliseconds: z
      .number()
      .min(0)
      .max(10_000)
      .default(10)
      .describe("How long to spin on a slow call, in ms (at most 10 s)"),
    Every: z
      .number()
      .int()
      .min(1)
      .default(1)
      .describe("Spin on every Every-th call (1 = on every call)"),
  }),
  inputs: { min: 1, max: 1, labels: ["signal"] },
  live: ["Milliseconds", "Every"],
  views: ["scope"],
  panel: "Scope of the forwarded signal.",
  create(ctx, p) {
    const info = ctx.inputs[0]!;
    const shape = info.isTimer ? (info.shape ?? { rows: 1, cols: 0 }) : signalInput(ctx, 0).shape;
    const out = ctx.output(shape);
    let ms = p.Milliseconds;
    let every = p.Every;
    let calls = 0;
    return {
      process(f) {
        calls++;
        if (calls >= every) {
          calls = 0;
          if (ms > 0) {
            const until = performance.now() + ms;
            while (performance.now() < until) {
              // spin
            }
          }
        }
        const n = f.n;
        const o = out.frame(n);
        o.copyEvents(f, 0, n, 0);
        out.emit(o);
      },
      reset() {
        calls = 0;
      },
      setParam(name, value) {
        if (name === "Milliseconds") ms = value as number;
        else if (name === "Every") every = value as number;
      },
    };
  },
});
