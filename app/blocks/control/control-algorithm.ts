import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  LegacyParamsError,
  legacyPair,
  vectorShape,
} from "../../engine";
import { vectorInput } from "../shared/inputs";
import { extendedNumber } from "../shared/params";
import { A, DOAS } from "./actuation";
import { MAX_ITEMS } from "../shared/limits";

/**
 * Strategies behind one interface (paper III-H): both turn one prediction vector into the next
 * actuation values, given the time since the previous prediction.
 */
interface Strategy {
  /** Writes the new target values of every DoF into `out` (before slew limiting and clipping). */
  step(
    pred: Float64Array,
    offset: number,
    dt: number,
    current: Float64Array,
    out: Float64Array,
  ): void;
}

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

function clip01(x: number): number {
  return x <= 0 ? 0 : x >= 1 ? 1 : x;
}

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
    const width = input.shape.cols;
    const dofs: DofSpec[] =
      p.DoFs ??
      Array.from({ length: width }, (_, k) => ({ Name: `dof${k}`, Positive: k, Rest: 0 }));
    const atRest: string[] = [];
    const oneSided: string[] = [];
    dofs.forEach((d, i) => {
      for (const [key, idx] of [
        ["Positive", d.Positive],
        ["Negative", d.Negative],
      ] as const) {
        if (idx !== undefined && idx >= width) {
          if (p.MissingPredictions === "rest") {
            if (key === "Positive") atRest.push(`${d.Name} (${idx})`);
            else if (d.Positive < width) oneSided.push(`${d.Name} (${idx})`);
            continue;
          }
          throw new BlockConfigError(
            `DoFs[${i}] (${d.Name}): ${key} ${idx} is out of range for input '${input.info.source}' with ${width} predictions (valid: 0–${width - 1})`,
            "DoFs",
          );
        }
      }
    });
    if (atRest.length > 0 || oneSided.length > 0) {
      ctx.warn(
        `input '${input.info.source}' has ${width} predictions` +
          (atRest.length > 0 ? `; at rest (no prediction): ${atRest.join(", ")}` : "") +
          (oneSided.length > 0 ? `; driven one way only: ${oneSided.join(", ")}` : ""),
      );
    }
    const m = dofs.length;
    if (Array.isArray(p.Safe) && p.Safe.length !== m) {
      throw new BlockConfigError(`Safe has ${p.Safe.length} values for ${m} DoFs`, "Safe");
    }
    // -1: no prediction (MissingPredictions: rest).
    const pos = Int32Array.from(dofs, (d) => (d.Positive < width ? d.Positive : -1));
    const neg = Int32Array.from(dofs, (d) =>
      d.Negative !== undefined && d.Negative < width ? d.Negative : -1,
    );
    const rest = Float64Array.from(dofs, (d) => d.Rest);
    const lo = Float64Array.from(dofs, (d) => d.Min ?? p.Min);
    const hi = Float64Array.from(dofs, (d) => d.Max ?? p.Max);
    dofs.forEach((d, i) => {
      if (lo[i]! > hi[i]!)
        throw new BlockConfigError(`DoFs[${i}] (${d.Name}): Min exceeds Max`, "DoFs");
    });
    const gain = new Float64Array(m);
    const dead = new Float64Array(m);
    let slew = p.SlewRate;
    let strategyName = p.Strategy;
    const applyParams = (): void => {
      for (let i = 0; i < m; i++) {
        gain[i] = dofs[i]!.Gain ?? p.Gain;
        dead[i] = dofs[i]!.DeadZone ?? p.DeadZone;
      }
    };
    applyParams();
    const activation = (x: number, i: number): number => {
      const a = clip01(x);
      const d = dead[i]!;
      return a <= d ? 0 : d >= 1 ? 0 : (a - d) / (1 - d);
    };
    const direct: Strategy = {
      step(pred, off, _dt, _cur, out) {
        for (let i = 0; i < m; i++) {
          if (pos[i]! < 0) {
            out[i] = rest[i]!;
            continue;
          }
          const up = activation(pred[off + pos[i]!]!, i);
          const down = neg[i]! >= 0 ? activation(pred[off + neg[i]!]!, i) : 0;
          out[i] = rest[i]! + gain[i]! * (up - down);
        }
      },
    };
    const stepwise: Strategy = {
      step(pred, off, dt, cur, out) {
        for (let i = 0; i < m; i++) {
          if (pos[i]! < 0) {
            out[i] = rest[i]!;
            continue;
          }
          const up = activation(pred[off + pos[i]!]!, i);
          const down = neg[i]! >= 0 ? activation(pred[off + neg[i]!]!, i) : 0;
          out[i] = cur[i]! + gain[i]! * (up - down) * dt;
        }
      },
    };
    let strategy = strategyName === "direct" ? direct : stepwise;
    const current = Float64Array.from(rest, (r, i) => Math.min(hi[i]!, Math.max(lo[i]!, r)));
    const target = new Float64Array(m);
    let lastT = NaN;
    let watchdogTripped = false;
    const nominalDt = ctx.desiredRate > 0 ? 1 / ctx.desiredRate : 0.04;
    const out = ctx.output(vectorShape(m));

    /** Slew limit and clip `target` into `current` over dt seconds. */
    const settle = (dt: number): void => {
      const maxStep = slew === Infinity ? Infinity : slew * dt;
      for (let i = 0; i < m; i++) {
        let v = target[i]!;
        if (v !== v) v = current[i]!; // a NaN prediction leaves the value where it is
        const d = v - current[i]!;
        if (d > maxStep) v = current[i]! + maxStep;
        else if (d < -maxStep) v = current[i]! - maxStep;
        current[i] = v < lo[i]! ? lo[i]! : v > hi[i]! ? hi[i]! : v;
      }
    };
    const describe = (): void => {
      ctx.setText(
        watchdogTripped
          ? `watchdog: no prediction for ${p.Timeout} s, sending ${Array.isArray(p.Safe) ? "the safe values" : p.Safe}`
          : `${strategyName}, ${m} DoF${m === 1 ? "" : "s"}`,
      );
    };
    describe();

    // Watchdog: a one-shot re-armed by every prediction, so it costs nothing while predictions
    // flow; once tripped it keeps sending the safe output at the desired rate (or 10 Hz).
    const safeHz = ctx.desiredRate > 0 ? ctx.desiredRate : 10;
    const trip = (t: number): void => {
      if (!watchdogTripped) {
        watchdogTripped = true;
        ctx.warn(`no prediction for ${p.Timeout} s: sending the safe output`);
        describe();
      }
      for (let i = 0; i < m; i++) {
        target[i] = p.Safe === "rest" ? rest[i]! : p.Safe === "hold" ? current[i]! : p.Safe[i]!;
      }
      settle(1 / safeHz);
      const f = out.frame(1);
      f.t[0] = t;
      for (let i = 0; i < m; i++) f.v[i] = current[i]!;
      out.emit(f);
      ctx.at(t + 1 / safeHz, trip);
    };
    let running = false;

    return {
      start() {
        running = true;
      },
      stop() {
        running = false;
      },
      process(f) {
        const o = out.frame(f.n);
        const s = f.stride;
        for (let e = 0; e < f.n; e++) {
          const t = f.t[e]!;
          const dt = lastT === lastT && t > lastT ? t - lastT : nominalDt;
          lastT = t;
          strategy.step(f.v, e * s, dt, current, target);
          settle(dt);
          o.t[e] = t;
          for (let i = 0; i < m; i++) o.v[e * m + i] = current[i]!;
        }
        if (watchdogTripped) {
          watchdogTripped = false;
          describe();
        }
        out.emit(o);
        if (p.Timeout > 0 && running) ctx.at(ctx.now() + p.Timeout, trip);
      },
      reset() {
        for (let i = 0; i < m; i++) current[i] = Math.min(hi[i]!, Math.max(lo[i]!, rest[i]!));
        lastT = NaN;
        watchdogTripped = false;
        describe();
      },
      setParam(name, value) {
        if (name === "Gain") p = { ...p, Gain: value as number };
        else if (name === "DeadZone") p = { ...p, DeadZone: value as number };
        else if (name === "SlewRate") slew = value as number;
        else if (name === "Strategy") {
          strategyName = value as Params["Strategy"];
          strategy = strategyName === "direct" ? direct : stepwise;
          describe();
        }
        applyParams();
      },
    };
  },
});
