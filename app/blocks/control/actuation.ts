/**
 * MOSAIC's data contract between a ControlAlgorithm and the devices it drives (BlenderArm,
 * HannesHand, HannesGUI). In the original the ControlAlgorithm sent a dictionary "degree of
 * actuation (DOA) → value 0..100" (MosaicLibary/Resources/AllEnums.cs, enum DOAs; filled by
 * DirectControlStrategy.cs and StepwiseControlStrategy.cs). Here frames are typed vectors: the
 * ControlAlgorithm's MOSAIC mapping sends the 11 DOAs it filled as one vector in the enum's order
 * (the enum's OpenHand, 9, was never a key), and the device blocks read it by position.
 *
 * Devices also accept what the original's examples wired into them by mistake (a plain
 * prediction vector, 0..1 per prediction, MOSAIC's 12–15 prediction layout): they map it as the
 * original's DirectControl would have, so the same file drives the same arm.
 */
import { BlockConfigError, formatShape, type BlockContext } from "../../engine";
import { inputName, vectorInput, type SignalInput } from "../shared/inputs";

/** One degree of actuation: its name, its DOAs enum value and its value at rest (0..100). */
export interface Doa {
  readonly name: string;
  readonly code: number;
  readonly rest: number;
}

/** The 11 degrees of actuation, in the order of a ControlAlgorithm's MOSAIC output. */
export const DOAS: readonly Doa[] = [
  { name: "ThumbFlexion", code: 0, rest: 0 },
  { name: "ThumbRotation", code: 1, rest: 0 },
  { name: "Index", code: 2, rest: 0 },
  { name: "Middle", code: 3, rest: 0 },
  { name: "Ring", code: 4, rest: 0 },
  { name: "Little", code: 5, rest: 0 },
  { name: "WristFlexionExtension", code: 6, rest: 50 },
  { name: "WristUlnarRadialDeviation", code: 7, rest: 50 },
  { name: "WristPronationSupination", code: 8, rest: 50 },
  { name: "ElbowFlexion", code: 10, rest: 0 },
  { name: "ElbowExtension", code: 11, rest: 0 },
];

/** Values in the actuation vector. */
export const ACTUATION_SIZE = DOAS.length;

/** Position of each degree of actuation in the actuation vector. */
export const A = {
  ThumbFlexion: 0,
  ThumbRotation: 1,
  Index: 2,
  Middle: 3,
  Ring: 4,
  Little: 5,
  WristFlexionExtension: 6,
  WristUlnarRadialDeviation: 7,
  WristPronationSupination: 8,
  ElbowFlexion: 9,
  ElbowExtension: 10,
} as const;

/**
 * MOSAIC's prediction layout (the comments of DirectControlStrategy.cs): 0 thumb flexion,
 * 1 thumb rotation, 2 index, 3 middle, 4 ring, 5 little, 6 wrist flexion, 7 wrist extension,
 * 8 pronation, 9 supination, 10 ulnar deviation, 11 radial deviation, 12 open hand, 13 elbow
 * flexion, 14 elbow extension; each 0..1.
 */
export const PREDICTION_SIZE = 15;

const clip = (x: number, lo: number, hi: number): number => (x < lo ? lo : x > hi ? hi : x);

/**
 * MOSAIC's DirectControl on one prediction vector (`width` values at `pred[off…]`) into an
 * actuation vector (11 values, 0..100), as the ControlAlgorithm block computes it: each
 * prediction clamped to 0..1, fingers 100·p, each wrist axis 50 + 50·(p⁺ − p⁻) (extension 7 /
 * flexion 6, ulnar 10 / radial 11, pronation 8 / supination 9), elbows 100·p. Predictions beyond
 * `width` count as absent: their degree stays at rest (a wrist axis with one side present uses
 * that side alone). Unlike the original, values are not truncated to whole numbers, a NaN
 * prediction counts as absent, and a negative prediction counts as 0 (the original clamped only
 * the result, so a negative flexion prediction moved the wrist towards extension).
 */
export function directActuation(
  pred: ArrayLike<number>,
  off: number,
  width: number,
  out: Float64Array,
  outOff = 0,
): void {
  const p = (i: number): number => {
    if (i >= width) return NaN;
    const v = pred[off + i]!;
    return v === v ? clip(v, 0, 1) : NaN;
  };
  for (let k = 0; k < 6; k++) {
    const v = p(k);
    out[outOff + k] = v === v ? 100 * v : DOAS[k]!.rest;
  }
  const axis = (plus: number, minus: number): number => {
    const a = p(plus);
    const b = p(minus);
    const hasA = a === a;
    const hasB = b === b;
    if (!hasA && !hasB) return 50;
    return 50 + 50 * ((hasA ? a : 0) - (hasB ? b : 0));
  };
  out[outOff + A.WristFlexionExtension] = axis(7, 6);
  out[outOff + A.WristUlnarRadialDeviation] = axis(10, 11);
  out[outOff + A.WristPronationSupination] = axis(8, 9);
  const e1 = p(13);
  const e2 = p(14);
  out[outOff + A.ElbowFlexion] = e1 === e1 ? 100 * e1 : 0;
  out[outOff + A.ElbowExtension] = e2 === e2 ? 100 * e2 : 0;
}

/** What a device block's control input carries. */
export type ControlKind = "actuation" | "prediction";

export interface ControlInput extends SignalInput {
  kind: ControlKind;
}

/**
 * The control input of a device block (BlenderArm, HannesHand, HannesGUI): an actuation vector
 * (a ControlAlgorithm's MOSAIC output, 11 values 0..100) or a plain prediction vector (12–15
 * values 0..1, mapped by `directActuation`). `mode` "auto" decides by the width: 11 values are an
 * actuation vector, 12 to 15 a prediction vector; `extra` lists other widths the block takes
 * as they are (BlenderArm's 9-value command), returned with kind undefined.
 */
export function controlInput(
  ctx: BlockContext,
  index: number,
  mode: "auto" | ControlKind,
  param: string,
  extra?: { width: number; what: string },
): ControlInput | (SignalInput & { kind: undefined }) {
  const s = vectorInput(ctx, index);
  const n = s.size;
  if (extra !== undefined && mode === "auto" && n === extra.width) return { ...s, kind: undefined };
  const want =
    `an actuation vector (${ACTUATION_SIZE} values 0–100, a ControlAlgorithm's MOSAIC output: ` +
    `${DOAS.map((d) => d.name).join(", ")}) or a prediction vector (12–${PREDICTION_SIZE} ` +
    "values 0–1 in MOSAIC's order)" +
    (extra !== undefined ? ` or ${extra.what}` : "");
  if (mode === "actuation") {
    if (n !== ACTUATION_SIZE) {
      throw new BlockConfigError(
        `${param} is actuation, but input ${inputName(s.info)} has shape ` +
          `${formatShape(s.shape)}; an actuation vector has ${ACTUATION_SIZE} values (${DOAS.map((d) => d.name).join(", ")})`,
        param,
      );
    }
    return { ...s, kind: "actuation" };
  }
  if (mode === "prediction") {
    if (n < 1 || n > PREDICTION_SIZE) {
      throw new BlockConfigError(
        `${param} is prediction, but input ${inputName(s.info)} has ${n} values; MOSAIC's ` +
          `prediction layout has at most ${PREDICTION_SIZE}`,
        param,
      );
    }
    return { ...s, kind: "prediction" };
  }
  if (n === ACTUATION_SIZE) return { ...s, kind: "actuation" };
  if (n >= 12 && n <= PREDICTION_SIZE) return { ...s, kind: "prediction" };
  throw new BlockConfigError(
    `input ${inputName(s.info)} has shape ${formatShape(s.shape)}; ${ctx.type} takes ${want}`,
    param,
  );
}

/** One line for the status: what the control input is read as. */
export function describeControl(c: { kind: ControlKind | undefined; size: number }): string {
  if (c.kind === "actuation") return "actuation vector (ControlAlgorithm)";
  if (c.kind === "prediction") return `${c.size} predictions (mapped as DirectControl)`;
  return `${c.size} values as they are`;
}

/**
 * Reads the control input's event `e` of frame values `v` (stride `size`) into an actuation
 * vector `out` (11 values 0..100).
 */
export function toActuation(
  c: { kind: ControlKind | undefined; size: number },
  v: Float64Array,
  e: number,
  out: Float64Array,
): void {
  const off = e * c.size;
  if (c.kind === "actuation") {
    for (let k = 0; k < ACTUATION_SIZE; k++) {
      const x = v[off + k]!;
      out[k] = x === x ? x : DOAS[k]!.rest;
    }
  } else {
    directActuation(v, off, c.size, out);
  }
}
