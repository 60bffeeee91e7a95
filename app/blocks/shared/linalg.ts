/**
 * Small dense linear algebra for blocks that handle 3-vectors, wrenches and projection matrices
 * (a few dozen numbers per event: plain TypeScript, no wasm call overhead). Matrices are
 * row-major `Float64Array`s.
 */
import { z } from "zod";
import { MAX_CHANNELS, MAX_ITEMS } from "./limits";

/**
 * The rotation R = Rz(yaw) · Ry(pitch) · Rx(roll) (angles in radians, right-handed, applied to
 * column vectors v' = R·v): first roll about x, then pitch about y, then yaw about z, all about
 * the fixed axes — the same as intrinsic z-y′-x″ (yaw, then pitch, then roll about the rotated
 * axes), the aerospace/ROS `rpy` convention. Writes 9 values, row-major, into `out`.
 */
export function rotationRPY(roll: number, pitch: number, yaw: number, out: Float64Array): void {
  const cr = Math.cos(roll);
  const sr = Math.sin(roll);
  const cp = Math.cos(pitch);
  const sp = Math.sin(pitch);
  const cy = Math.cos(yaw);
  const sy = Math.sin(yaw);
  out[0] = cy * cp;
  out[1] = cy * sp * sr - sy * cr;
  out[2] = cy * sp * cr + sy * sr;
  out[3] = sy * cp;
  out[4] = sy * sp * sr + cy * cr;
  out[5] = sy * sp * cr - cy * sr;
  out[6] = -sp;
  out[7] = cp * sr;
  out[8] = cp * cr;
}

/** A matrix param: a list of rows, every row the same length. */
export const matrixParam = () =>
  z
    .array(z.array(z.number()).min(1).max(MAX_CHANNELS))
    .min(1)
    .max(MAX_ITEMS)
    .refine((m) => m.every((r) => r.length === m[0]!.length), {
      message: "every row of the matrix must have the same length",
    });

/** Copies a list of rows into a row-major array. */
export function flattenRows(m: readonly (readonly number[])[]): Float64Array {
  const cols = m[0]?.length ?? 0;
  const out = new Float64Array(m.length * cols);
  m.forEach((row, r) => row.forEach((x, c) => (out[r * cols + c] = x)));
  return out;
}
