/**
 * The TAC's create-time checks (tac.ts): which input is the control and which the target, their
 * widths, per-DoF values (Tolerance, Random's Low and High) and the list of targets of `Targets`.
 */
import { BlockConfigError, type BlockContext } from "../../engine";
import { inputName, vectorInput } from "../shared/inputs";
import { SeededRandom } from "../shared/random";

/** Most trials, and most target values (trials × DoFs) a TAC keeps. */
export const MAX_TRIALS = 10_000;
export const MAX_TARGET_VALUES = 1_000_000;

/** `Targets`: a list of target vectors, or random ones. */
export type TargetsParam =
  | number[][]
  | {
      Random: {
        Count: number;
        Seed: number;
        Low: number | number[];
        High: number | number[];
      };
    };

/** A number for every DoF, or one per DoF (`what` and `param` name it in the message). */
export type PerDof = (v: number | number[], what: string, param: string) => Float64Array;

export interface TacPorts {
  /** Port of the control input and of the target input (which may be absent). */
  control: number;
  target: number;
  /** DoFs: values per control (and target) event. */
  D: number;
  hasTargetInput: boolean;
  perDof: PerDof;
}

/** The inputs as `Order` says, checked against each other and against Targets and Stimulus. */
export function tacPorts(
  ctx: BlockContext,
  order: "control-target" | "target-control",
  targets: TargetsParam | undefined,
  stimulus: string | undefined,
): TacPorts {
  const ci = order === "control-target" ? 0 : 1;
  const ti = 1 - ci;
  if (ci >= ctx.inputs.length) {
    throw new BlockConfigError("Order target-control needs two inputs: [target, control]", "Order");
  }
  const control = vectorInput(ctx, ci);
  const D = control.size;
  const targetIn = ti < ctx.inputs.length ? vectorInput(ctx, ti) : null;
  if (targetIn !== null && targetIn.size !== D) {
    throw new BlockConfigError(
      `the target input ${inputName(targetIn.info)} has ${targetIn.size} values, but the control ` +
        `input ${inputName(control.info)} has ${D}: they must match`,
    );
  }
  if (targetIn !== null && targets !== undefined) {
    throw new BlockConfigError(
      "give Targets or a target input, not both (targets come from one of them)",
      "Targets",
    );
  }
  if (stimulus !== undefined && targets !== undefined) {
    throw new BlockConfigError(
      `give Targets or Stimulus, not both (the trials are the captures of Stimulus '${stimulus}')`,
      "Targets",
    );
  }
  if (targetIn === null && targets === undefined && stimulus === undefined) {
    throw new BlockConfigError(
      "give Targets (a list of target vectors or { Random: { Count } }) or a second input with targets",
      "Targets",
    );
  }
  const perDof: PerDof = (v, what, param) => {
    if (typeof v === "number") return new Float64Array(D).fill(v);
    if (v.length !== D) {
      throw new BlockConfigError(
        `${what} has ${v.length} values, but the control input ${inputName(control.info)} has ${D} DoFs`,
        param,
      );
    }
    return Float64Array.from(v);
  };
  return { control: ci, target: ti, D, hasTargetInput: targetIn !== null, perDof };
}

/** The targets of `Targets` (none when left out). */
export function targetList(
  targets: TargetsParam | undefined,
  D: number,
  perDof: PerDof,
): Float64Array[] {
  if (targets === undefined) return [];
  if (!Array.isArray(targets)) return randomTargets(targets.Random, D, perDof);
  if (targets.length * D > MAX_TARGET_VALUES) {
    throw new BlockConfigError(`too many target values (at most ${MAX_TARGET_VALUES})`, "Targets");
  }
  return targets.map((v, i) => perDof(v, `Targets[${i}]`, "Targets"));
}

/** `{ Random: … }`: Count targets drawn uniformly between Low and High, one value per DoF. */
function randomTargets(
  r: Extract<TargetsParam, { Random: unknown }>["Random"],
  D: number,
  perDof: PerDof,
): Float64Array[] {
  if (r.Count * D > MAX_TARGET_VALUES) {
    throw new BlockConfigError(
      `${r.Count} random targets of ${D} DoFs are too many values (at most ${MAX_TARGET_VALUES})`,
      "Targets",
    );
  }
  const lo = perDof(r.Low, "Targets.Random.Low", "Targets");
  const hi = perDof(r.High, "Targets.Random.High", "Targets");
  const rng = new SeededRandom(r.Seed);
  const list: Float64Array[] = [];
  for (let k = 0; k < r.Count; k++) {
    const v = new Float64Array(D);
    for (let i = 0; i < D; i++) v[i] = lo[i]! + (hi[i]! - lo[i]!) * rng.uniform();
    list.push(v);
  }
  return list;
}
