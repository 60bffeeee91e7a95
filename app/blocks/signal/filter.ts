import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  errorMessage,
  legacyVector,
  LegacyParamsError,
} from "../../engine";
import { FilterBank } from "../../engine/dsp";
import { requireDsp } from "../shared/dsp";
import { signalInput } from "../shared/inputs";
import { MAX_COEFFICIENTS } from "../shared/limits";

export const Filter = defineBlock({
  type: "Filter",
  category: "Signal processing",
  summary: "IIR or FIR filter applied to every channel independently (difference equation).",
  help:
    "Implements the difference equation of the paper (III-F, eq. 1) on every channel: " +
    "y[n] = Σ_{i=0..P} m_i·x[n−i] − Σ_{j=1..Q} d_j·y[n−j], with Numerator m = [m_0, …, m_P] " +
    "and Denominator d = [1, d_1, …, d_Q]; Denominator [1] gives an FIR filter. This is " +
    "`scipy.signal.lfilter(b, a, x)` with zero initial state, so coefficients designed with " +
    "`scipy.signal.butter` (or MATLAB's `butter`) can be pasted in. A matrix input (e.g. a window) " +
    "is filtered element by element, each element being its own channel over time. The `reset` " +
    "action clears the filter history. Timestamps are copied.",
  params: z
    .strictObject({
      Numerator: z
        .array(z.number())
        .min(1)
        .max(MAX_COEFFICIENTS)
        .describe("Feedforward coefficients m_0 … m_P (SciPy's b)"),
      Denominator: z
        .array(z.number())
        .min(1)
        .max(MAX_COEFFICIENTS)
        .default([1])
        .describe("Feedback coefficients 1, d_1 … d_Q (SciPy's a); [1] gives an FIR filter"),
    })
    .refine((p) => p.Denominator[0] === 1, {
      message:
        "Denominator must start with 1 (d_0 = 1 by convention); divide all coefficients by the " +
        "first one",
      path: ["Denominator"],
    }),
  legacyParams(args) {
    if (args.length < 1 || args.length > 2) {
      throw new LegacyParamsError(
        `expected [numerator, denominator] (the denominator is optional), got ${args.length} arguments`,
      );
    }
    const out: { Numerator: number[]; Denominator?: number[] } = {
      Numerator: legacyVector(args[0]!, "numerator", "Numerator"),
    };
    if (args[1] !== undefined && args[1].trim() !== "") {
      out.Denominator = legacyVector(args[1], "denominator", "Denominator");
    }
    return out;
  },
  legacyForm: "[b0;b1;b2, 1;a1;a2]: numerator and (optional) denominator as a;b;c vectors",
  inputs: { min: 1, max: 1, labels: ["signal"] },
  views: ["scope"],
  panel: "Scope of the filtered channels.",
  create(ctx, p) {
    requireDsp(ctx.type);
    const sig = signalInput(ctx, 0);
    let bank: FilterBank;
    try {
      bank = new FilterBank(p.Numerator, p.Denominator, sig.size);
    } catch (e) {
      throw new BlockConfigError(`cannot create the filter: ${errorMessage(e)}`, "Numerator");
    }
    const out = ctx.output(sig.shape);
    return {
      process(f) {
        const n = f.n;
        if (n === 0) return;
        const o = out.frame(n);
        const ft = f.t;
        for (let e = 0; e < n; e++) o.t[e] = ft[e]!;
        bank.process(f.v, o.v, n);
        out.emit(o);
      },
      reset() {
        bank.reset();
      },
      dispose() {
        bank.dispose();
      },
    };
  },
});
