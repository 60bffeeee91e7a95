/**
 * The ControlAlgorithm's degrees of freedom (control-algorithm.ts): the predictions that drive
 * each, checked against the input's width (missing ones at rest, or an error), their rest values
 * and limits, and the two strategies that turn a prediction vector into target values.
 */
import { BlockConfigError, type BlockContext } from "../../engine";
import type { SignalInput } from "../shared/inputs";

/** One DoF as the `DoFs` param gives it (control-algorithm.ts). */
export interface DofParam {
  Name: string;
  Positive: number;
  Negative?: number | undefined;
  Rest: number;
  Gain?: number | undefined;
  DeadZone?: number | undefined;
  Min?: number | undefined;
  Max?: number | undefined;
}

/** The params the DoF table reads. */
export interface DofDefaults {
  DoFs?: DofParam[] | undefined;
  MissingPredictions: "error" | "rest";
  Min: number;
  Max: number;
  Safe: "rest" | "hold" | number[];
}

/** The DoFs as arrays, one value per DoF. */
export interface DofTable {
  specs: DofParam[];
  m: number;
  /** Index of the prediction that drives the DoF up / down; -1: none. */
  pos: Int32Array;
  neg: Int32Array;
  rest: Float64Array;
  lo: Float64Array;
  hi: Float64Array;
}

/** The DoFs of `p` (default: one per prediction) for `input`, checked. */
export function dofTable(ctx: BlockContext, p: DofDefaults, input: SignalInput): DofTable {
  const width = input.shape.cols;
  const specs: DofParam[] =
    p.DoFs ?? Array.from({ length: width }, (_, k) => ({ Name: `dof${k}`, Positive: k, Rest: 0 }));
  checkPredictions(ctx, specs, p.MissingPredictions, input);
  const m = specs.length;
  if (Array.isArray(p.Safe) && p.Safe.length !== m) {
    throw new BlockConfigError(`Safe has ${p.Safe.length} values for ${m} DoFs`, "Safe");
  }
  // -1: no prediction (MissingPredictions: rest).
  const pos = Int32Array.from(specs, (d) => (d.Positive < width ? d.Positive : -1));
  const neg = Int32Array.from(specs, (d) =>
    d.Negative !== undefined && d.Negative < width ? d.Negative : -1,
  );
  const rest = Float64Array.from(specs, (d) => d.Rest);
  const lo = Float64Array.from(specs, (d) => d.Min ?? p.Min);
  const hi = Float64Array.from(specs, (d) => d.Max ?? p.Max);
  specs.forEach((d, i) => {
    if (lo[i]! > hi[i]!)
      throw new BlockConfigError(`DoFs[${i}] (${d.Name}): Min exceeds Max`, "DoFs");
  });
  return { specs, m, pos, neg, rest, lo, hi };
}

/**
 * Prediction indices beyond the input's width: an error, or (MissingPredictions: rest) one
 * warning naming the DoFs left at rest and those driven one way only.
 */
function checkPredictions(
  ctx: BlockContext,
  specs: DofParam[],
  missing: "error" | "rest",
  input: SignalInput,
): void {
  const width = input.shape.cols;
  const atRest: string[] = [];
  const oneSided: string[] = [];
  specs.forEach((d, i) => {
    for (const [key, idx] of [
      ["Positive", d.Positive],
      ["Negative", d.Negative],
    ] as const) {
      if (idx !== undefined && idx >= width) {
        if (missing === "rest") {
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
}

/**
 * Strategies behind one interface (paper III-H): both turn one prediction vector into the next
 * actuation values, given the time since the previous prediction.
 */
export interface Strategy {
  /** Writes the new target values of every DoF into `out` (before slew limiting and clipping). */
  step(
    pred: Float64Array,
    offset: number,
    dt: number,
    current: Float64Array,
    out: Float64Array,
  ): void;
}

function clip01(x: number): number {
  return x <= 0 ? 0 : x >= 1 ? 1 : x;
}

/**
 * Each DoF's activation a⁺ − a⁻ from one prediction vector, with its gain and dead zone (both
 * live): `direct` maps it to a value around Rest, `stepwise` to a change per second.
 */
export class DofDrive {
  readonly gain: Float64Array;
  readonly dead: Float64Array;
  readonly direct: Strategy;
  readonly stepwise: Strategy;

  constructor(private readonly dofs: DofTable) {
    this.gain = new Float64Array(dofs.m);
    this.dead = new Float64Array(dofs.m);
    const { m, pos, rest } = dofs;
    const gain = this.gain;
    this.direct = {
      step: (pred, off, _dt, _cur, out) => {
        for (let i = 0; i < m; i++) {
          out[i] = pos[i]! < 0 ? rest[i]! : rest[i]! + gain[i]! * this.activation(pred, off, i);
        }
      },
    };
    this.stepwise = {
      step: (pred, off, dt, cur, out) => {
        for (let i = 0; i < m; i++) {
          out[i] = pos[i]! < 0 ? rest[i]! : cur[i]! + gain[i]! * this.activation(pred, off, i) * dt;
        }
      },
    };
  }

  /** Each DoF's Gain and DeadZone, or the block's. */
  apply(blockGain: number, blockDeadZone: number): void {
    const { specs, m } = this.dofs;
    for (let i = 0; i < m; i++) {
      this.gain[i] = specs[i]!.Gain ?? blockGain;
      this.dead[i] = specs[i]!.DeadZone ?? blockDeadZone;
    }
  }

  /** a⁺ − a⁻ of DoF `i` (one that has a Positive prediction) from the predictions at `off`. */
  private activation(pred: Float64Array, off: number, i: number): number {
    const { pos, neg } = this.dofs;
    const up = this.scaled(pred[off + pos[i]!]!, i);
    const down = neg[i]! >= 0 ? this.scaled(pred[off + neg[i]!]!, i) : 0;
    return up - down;
  }

  /** Clamped to [0, 1]; at or below the dead zone 0, the rest rescaled from zero. */
  private scaled(x: number, i: number): number {
    const a = clip01(x);
    const d = this.dead[i]!;
    return a <= d ? 0 : d >= 1 ? 0 : (a - d) / (1 - d);
  }
}
