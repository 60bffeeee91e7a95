/**
 * The Blender arm's UDP datagram (docs/protocols.md, "BlenderArm"): the ASCII text
 * `[a,b,c,d,e,f,g,h,i]`, nine numbers — six finger flexions 0..1 (thumb flexion, thumb rotation,
 * index, middle, ring, little), then wrist flexion/extension, ulnar/radial deviation and
 * supination/pronation, each −1..1 — as the original's BlenderArm.cs wrote them for its Blender
 * scene's script (3DHands_left.py).
 */
import { A, ACTUATION_SIZE } from "../control/actuation";

/** Values in a Blender arm command. */
export const BLENDER_SIZE = 9;

/**
 * Actuation (11 values 0..100, actuation.ts order) → the nine command values. Fingers /100;
 * wrist flexion/extension and ulnar/radial deviation /50 − 1 (flexion −1, extension 1; ulnar −1,
 * radial 1 per the original's comments); pronation/supination 1 − value/50. The original wrote
 * −value/50 − 1 for the last one, −2 at rest and never within −1..1 (its `-1*` applied before the
 * division's `- 1`); we send the negation it evidently meant, −(value/50 − 1), so rest is 0.
 * Value 100 (prediction 8, "pronation" in the original's prediction layout) is then −1, which
 * the file's header comment calls supination: the original's two statements disagree, and only
 * the code's sign was deliberate.
 */
export function blenderCommand(act: ArrayLike<number>, out: Float64Array): void {
  if (act.length < ACTUATION_SIZE) throw new Error("blenderCommand: need 11 actuation values");
  for (let k = 0; k < 6; k++) out[k] = act[k]! / 100;
  out[6] = act[A.WristFlexionExtension]! / 50 - 1;
  out[7] = act[A.WristUlnarRadialDeviation]! / 50 - 1;
  out[8] = 1 - act[A.WristPronationSupination]! / 50;
}

/** A number as the datagram writes it: shortest round-trip decimal, "0" for −0, "NaN" for NaN. */
function num(x: number): string {
  if (x === 0) return "0";
  return String(x);
}

/** The datagram text of `n` values at `v[off…]`: "[a,b,…]". */
export function blenderText(v: ArrayLike<number>, off = 0, n = BLENDER_SIZE): string {
  let s = "[";
  for (let k = 0; k < n; k++) s += (k > 0 ? "," : "") + num(v[off + k]!);
  return s + "]";
}

/** The text as ASCII bytes (the datagram). */
export function asciiBytes(s: string): Uint8Array {
  const b = new Uint8Array(s.length);
  for (let i = 0; i < s.length; i++) b[i] = s.charCodeAt(i) & 0x7f;
  return b;
}
