import { z } from "zod";
import { defineBlock, LegacyParamsError, legacyPair } from "../../engine";
import { vectorInput } from "../shared/inputs";
import { extendedNumber } from "../shared/params";
import { A, DOAS } from "./actuation";
import { MAX_ITEMS } from "../shared/limits";
import { ControlRun } from "./control-algorithm-run";
import { dofTable } from "./control-dofs";

const dof = z.strictObject({
  Name: z.string().min(1).describe("Name of the degree of freedom (shown in the panel)"),
  Positive: z
    .number()
    .int()
    .min(0)
    .describe("Index of the prediction that drives this DoF up (e.g. flexion)"),
  Negative: z
    .number()
    .int()
    .min(0)
    .optional()
    .describe("Index of the prediction that drives it down (e.g. extension); none = one-sided"),
  Rest: z
    .number()
    .default(0)
    .describe("Value at rest (no activation), e.g. 50 for a wrist at neutral"),
  Gain: z
    .number()
    .optional()
    .describe(
      "Direct: value per unit of activation; stepwise: change per second at full activation (default: the block's Gain)",
    ),
  DeadZone: z
    .number()
    .min(0)
    .optional()
    .describe("Activations below this are ignored (default: the block's DeadZone)"),
  Min: z.number().optional().describe("Lowest value sent (default: the block's Min)"),
  Max: z.number().optional().describe("Highest value sent (default: the block's Max)"),
});

type DofSpec = z.output<typeof dof>;

/**
 * MOSAIC's hand mapping (its DirectControlStrategy.cs / StepwiseControlStrategy.cs) as DoF specs,
 * in the order of its DOAs enum (actuation.ts): fingers from predictions 0–5, the wrist axes from
 * the differences 7 − 6 (extension − flexion), 10 − 11 (ulnar − radial) and 8 − 9 (pronation −
 * supination) around 50, elbow flexion and extension from 13 and 14. Stepwise control also closes
 * the fingers with prediction 12 ("open hand"), as the original's; direct control ignores it, as
 * the original's did.
 */
export function mosaicHandDofs(strategy: "direct" | "stepwise" = "direct"): DofSpec[] {
  const open = strategy === "stepwise" ? { Negative: 12 } : {};
  const finger = (i: number): DofSpec => ({
    Name: DOAS[i]!.name,
    Positive: i,
    ...open,
    Rest: 0,
  });
  const axis = (k: number, plus: number, minus: number): DofSpec => ({
    Name: DOAS[k]!.name,
    Positive: plus,
    Negative: minus,
    Rest: 50,
    Gain: 50,
  });
  return [
    finger(0),
    finger(1),
    finger(2),
    finger(3),
    finger(4),
    finger(5),
    axis(A.WristFlexionExtension, 7, 6),
    axis(A.WristUlnarRadialDeviation, 10, 11),
    axis(A.WristPronationSupination, 8, 9),
    { Name: DOAS[A.ElbowFlexion]!.name, Positive: 13, Rest: 0 },
    { Name: DOAS[A.ElbowExtension]!.name, Positive: 14, Rest: 0 },
  ];
}

const params = z
  .strictObject({
    Strategy: z
      .enum(["direct", "stepwise"])
      .default("direct")
      .describe(
        "direct: value = Rest + Gain·(positive − negative activation), proportional position/force; " +
          "stepwise: value changes by Gain per second at full activation (velocity control)",
      ),
    DoFs: z
      .array(dof)
      .min(1)
      .max(MAX_ITEMS)
      .optional()
      .describe(
        "Degrees of freedom and the predictions that drive them; default: one DoF per prediction (DoF k driven by prediction k)",
      ),
    Gain: z
      .number()
      .default(100)
      .describe(
        "Direct: output per unit of activation; stepwise: change per second at full activation",
      ),
    DeadZone: z
      .number()
      .min(0)
      .default(0)
      .describe("Activations at or below this are treated as zero (and the rest starts from zero)"),
    MissingPredictions: z
      .enum(["error", "rest"])
      .default("error")
      .describe(
        "A DoF whose Positive index is beyond the input's predictions: error (at load), or rest " +
          "(it stays at Rest, and a missing Negative is left out; one warning at load says which), " +
          "e.g. MOSAIC's 15-prediction mapping fed with 12 or 13 predictions",
      ),
    Min: z.number().default(0).describe("Lowest output value"),
    Max: z.number().default(100).describe("Highest output value"),
    SlewRate: extendedNumber()
      .default(Infinity)
      .describe("Largest change of an output per second (.inf = unlimited)"),
    Timeout: z
      .number()
      .min(0)
      .default(0.5)
      .describe(
        "Watchdog: seconds without a prediction before the safe output is sent (0 = off); it needs DesiredRate or a periodic input",
      ),
    Safe: z
      .union([z.enum(["rest", "hold"]), z.array(z.number()).max(MAX_ITEMS)])
      .default("rest")
      .describe(
        "What the watchdog sends when predictions stop: each DoF's Rest, its last value (hold), or these values",
      ),
  })
  .refine((p) => p.Min <= p.Max, { message: "Min must not exceed Max", path: ["Min"] });

type Params = z.output<typeof params>;

export const ControlAlgorithm = defineBlock({
  type: "ControlAlgorithm",
  category: "Control",
  summary:
    "Maps prediction vectors to actuation commands (direct or stepwise control) with limits and a watchdog.",
  help:
    "The interface between a model's predictions and a device (paper III-H). Each degree of " +
    "freedom (DoF) is driven by one prediction (or by the difference of an agonist and an " +
    "antagonist prediction). With Strategy `direct`, activations map proportionally to positions " +
    "or forces: value = Rest + Gain·(a⁺ − a⁻); with `stepwise`, they move the value at a speed " +
    "proportional to the activation: value += Gain·(a⁺ − a⁻)·Δt (velocity control, Egle et al. in " +
    "the paper's IV-A). Activations are clamped to [0, 1]; those at or below DeadZone count as " +
    "zero and the remainder is rescaled from zero. The output is then limited to SlewRate per " +
    "second and clipped to [Min, Max]. A watchdog sends the Safe output when no prediction arrived " +
    "for Timeout seconds (a stalled model must not leave a prosthesis moving). MOSAIC's " +
    "`[algorithm:DirectControl]` and `[algorithm:StepwiseControl]` load with its 15-prediction hand " +
    "mapping: 11 DoFs, 0–100, in the order of its DOAs enum (ThumbFlexion, ThumbRotation, Index, " +
    "Middle, Ring, Little, WristFlexionExtension, WristUlnarRadialDeviation, " +
    "WristPronationSupination, ElbowFlexion, ElbowExtension; wrist axes at 50), the vector that " +
    "BlenderArm, HannesHand and HannesGUI read. Its predictions 12 (open hand, stepwise only), 13 " +
    "and 14 (elbow) are often absent: the examples' models predict 12 or 13 values, which made the " +
    "original fail on every prediction; here the missing degrees stay at rest (one warning at " +
    "load). Unlike the original, values are not truncated to whole numbers, stepwise control also " +
    "moves ulnar/radial deviation and elbow extension, and both strategies turn the wrist the same " +
    "way (the original's stepwise pronation/supination ran opposite to its direct control).",
  params,
  legacyParams: (args) => {
    const p = legacyPair(args[0] ?? "");
    if (p.key !== "algorithm") {
      throw new LegacyParamsError(
        `expected 'algorithm:DirectControl' or 'algorithm:StepwiseControl', got '${args[0] ?? ""}'`,
        "Strategy",
      );
    }
    // The enum parse of the original tolerated spaces around the name.
    const algorithm = p.value.trim();
    if (algorithm === "DirectControl") {
      return {
        Strategy: "direct",
        DoFs: mosaicHandDofs("direct"),
        Gain: 100,
        Min: 0,
        Max: 100,
        MissingPredictions: "rest",
      };
    }
    if (algorithm === "StepwiseControl") {
      // MOSAIC stepped by (p − 0.3)·100/25 per prediction (at 25 Hz: 100·(p − 0.3) per second);
      // here activations above the 0.3 dead zone are rescaled by 1/0.7, hence a gain of 70.
      return {
        Strategy: "stepwise",
        DoFs: mosaicHandDofs("stepwise").map((d) => ({ ...d, Gain: 70 })),
        Gain: 70,
        DeadZone: 0.3,
        Min: 0,
        Max: 100,
        MissingPredictions: "rest",
      };
    }
    throw new LegacyParamsError(
      `unknown algorithm '${algorithm}' (MOSAIC had DirectControl and StepwiseControl)`,
      "Strategy",
    );
  },
  legacyForm: "[algorithm:DirectControl] or [algorithm:StepwiseControl] (MOSAIC's hand mapping)",
  inputs: { min: 1, max: 1, labels: ["predictions"] },
  live: ["Gain", "DeadZone", "SlewRate", "Strategy"],
  views: ["spider", "scope", "label"],
  panel: "One bar per DoF with its current value and limits, the strategy, and the watchdog state.",
  create(ctx, p: Params) {
    const input = vectorInput(ctx, 0);
    const dofs = dofTable(ctx, p, input);
    return new ControlRun(ctx, dofs, {
      strategy: p.Strategy,
      gain: p.Gain,
      deadZone: p.DeadZone,
      slewRate: p.SlewRate,
      timeout: p.Timeout,
      safe: p.Safe,
    }).instance();
  },
});
