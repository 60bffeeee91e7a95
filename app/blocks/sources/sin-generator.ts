import { z } from "zod";
import {
  defineBlock,
  legacyInteger,
  legacyNumber,
  LegacyParamsError,
  vectorShape,
} from "../../engine";
import { timerInput } from "../shared/inputs";

const TAU = 2 * Math.PI;

export const SinGenerator = defineBlock({
  type: "SinGenerator",
  category: "Sources",
  summary: "Sine waves on every tick of its timer: component i is A·sin(2πf·t + φ + i·PhaseStep).",
  help:
    "Generates synthetic sinusoids for testing and teaching (paper Table 3). On every tick of its " +
    "timer input it emits one vector whose component i (0-based) is " +
    "`Amplitude · sin(2π · Frequency · (t − t0) + Phase + i · PhaseStep)`, where t is the tick's " +
    "timestamp and t0 the time the pipeline started (so the waves start at their phase when the " +
    "pipeline starts, and the time difference keeps full precision). MOSAIC offset the phase of " +
    "component i by 10·i radians; PhaseStep keeps that default. Amplitude, Frequency and Phase " +
    "can be changed while running; a new Frequency continues the wave without a phase jump.",
  params: z.strictObject({
    Components: z
      .number()
      .int()
      .min(1)
      .max(4096)
      .default(1)
      .describe("Number of sine components, i.e. the width of the output vector"),
    Amplitude: z.number().default(1).describe("Peak amplitude of every component"),
    Frequency: z.number().default(0.2).describe("Frequency of every component, in Hz"),
    Phase: z.number().default(0).describe("Phase of component 0 at the pipeline start, in radians"),
    PhaseStep: z
      .number()
      .default(10)
      .describe(
        "Phase added per component, in radians: component i starts at Phase + i·PhaseStep " +
          "(MOSAIC used 10)",
      ),
  }),
  legacyParams(args) {
    if (args.length > 4) {
      throw new LegacyParamsError(
        `expected at most 4 arguments [d, G, nu, phi], got ${args.length}`,
      );
    }
    const out: Record<string, number> = {};
    if (args[0] !== undefined)
      out.Components = legacyInteger(args[0], "d (components)", "Components");
    if (args[1] !== undefined) out.Amplitude = legacyNumber(args[1], "G (amplitude)", "Amplitude");
    if (args[2] !== undefined) out.Frequency = legacyNumber(args[2], "nu (frequency)", "Frequency");
    if (args[3] !== undefined) out.Phase = legacyNumber(args[3], "phi (phase)", "Phase");
    return out;
  },
  legacyForm:
    "[d, G, nu, phi]: components, amplitude, frequency in Hz, phase in rad (1 to 4 numbers)",
  inputs: { min: 1, max: 1, labels: ["timer"] },
  live: ["Amplitude", "Frequency", "Phase"],
  views: ["scope", "spider"],
  panel: "Scope of the generated components.",
  create(ctx, p) {
    timerInput(ctx, 0);
    const n = p.Components;
    const out = ctx.output(vectorShape(n));
    let amplitude = p.Amplitude;
    let frequency = p.Frequency;
    let phase = p.Phase;
    const step = p.PhaseStep;
    // The wave is A·sin(2πf(t − tRef) + acc + φ + i·step); a live Frequency change moves tRef to
    // the change time and folds the phase reached so far into acc.
    let tRef = NaN;
    let acc = 0;
    return {
      process(f) {
        if (Number.isNaN(tRef)) tRef = ctx.startTime;
        const m = f.n;
        const o = out.frame(m);
        const ot = o.t;
        const ov = o.v;
        const ft = f.t;
        const w = TAU * frequency;
        for (let e = 0; e < m; e++) {
          const t = ft[e]!;
          ot[e] = t;
          const base = w * (t - tRef) + acc + phase;
          const off = e * n;
          for (let i = 0; i < n; i++) ov[off + i] = amplitude * Math.sin(base + i * step);
        }
        out.emit(o);
      },
      reset() {
        tRef = NaN;
        acc = 0;
      },
      setParam(name, value) {
        const v = value as number;
        if (name === "Amplitude") amplitude = v;
        else if (name === "Phase") phase = v;
        else if (name === "Frequency") {
          const now = ctx.now();
          if (!Number.isNaN(tRef)) {
            acc = (acc + TAU * frequency * (now - tRef)) % TAU;
            tRef = now;
          }
          frequency = v;
        }
      },
    };
  },
});
