/**
 * Unit quaternions for the kinematics blocks: scalar first [w, x, y, z], Hamilton product, active
 * rotations (`q ⊗ v ⊗ q*` turns a vector expressed in the rotated frame into the reference
 * frame). Functions read and write at offsets into Float64Arrays, so that a block's hot path
 * allocates nothing.
 */

/** Below this norm a quaternion carries no orientation (refused rather than normalised). */
export const MIN_QUATERNION_NORM = 1e-9;

/** The identity rotation. */
export const IDENTITY: readonly number[] = [1, 0, 0, 0];

/**
 * `out[o…o+4) = a ⊗ b` (apply b, then a). `out` may be `a` or `b` only at a different offset;
 * the product is computed into locals first, so aliasing is harmless.
 */
export function multiply(
  a: ArrayLike<number>,
  ai: number,
  b: ArrayLike<number>,
  bi: number,
  out: Float64Array,
  o: number,
): void {
  const aw = a[ai]!,
    ax = a[ai + 1]!,
    ay = a[ai + 2]!,
    az = a[ai + 3]!;
  const bw = b[bi]!,
    bx = b[bi + 1]!,
    by = b[bi + 2]!,
    bz = b[bi + 3]!;
  out[o] = aw * bw - ax * bx - ay * by - az * bz;
  out[o + 1] = aw * bx + ax * bw + ay * bz - az * by;
  out[o + 2] = aw * by - ax * bz + ay * bw + az * bx;
  out[o + 3] = aw * bz + ax * by - ay * bx + az * bw;
}

/** `out[o…o+4) = a ⊗ b*` (b's inverse, b being a unit quaternion). */
export function multiplyConjugate(
  a: ArrayLike<number>,
  ai: number,
  b: ArrayLike<number>,
  bi: number,
  out: Float64Array,
  o: number,
): void {
  const aw = a[ai]!,
    ax = a[ai + 1]!,
    ay = a[ai + 2]!,
    az = a[ai + 3]!;
  const bw = b[bi]!,
    bx = -b[bi + 1]!,
    by = -b[bi + 2]!,
    bz = -b[bi + 3]!;
  out[o] = aw * bw - ax * bx - ay * by - az * bz;
  out[o + 1] = aw * bx + ax * bw + ay * bz - az * by;
  out[o + 2] = aw * by - ax * bz + ay * bw + az * bx;
  out[o + 3] = aw * bz + ax * by - ay * bx + az * bw;
}

/**
 * Copies the quaternion at `src[si…si+4)` to `out[o…o+4)` scaled to unit norm; returns false (and
 * writes nothing) when a component is not finite or the norm is below MIN_QUATERNION_NORM.
 */
export function normalizeInto(
  src: ArrayLike<number>,
  si: number,
  out: Float64Array,
  o: number,
): boolean {
  const w = src[si]!,
    x = src[si + 1]!,
    y = src[si + 2]!,
    z = src[si + 3]!;
  const norm = Math.sqrt(w * w + x * x + y * y + z * z);
  if (!Number.isFinite(norm) || norm < MIN_QUATERNION_NORM) return false;
  out[o] = w / norm;
  out[o + 1] = x / norm;
  out[o + 2] = y / norm;
  out[o + 3] = z / norm;
  return true;
}

/** Why `normalizeInto` refused the quaternion at `src[si…si+4)`. */
export function refusalReason(src: ArrayLike<number>, si: number): string {
  for (let k = 0; k < 4; k++) {
    if (!Number.isFinite(src[si + k]!)) return "a component is not a finite number";
  }
  return "its norm is zero";
}

/** Negates the quaternion at `q[o…o+4)` when w < 0 (q and −q are the same rotation). */
export function canonicalize(q: Float64Array, o: number): void {
  if (q[o]! < 0) {
    q[o] = -q[o]!;
    q[o + 1] = -q[o + 1]!;
    q[o + 2] = -q[o + 2]!;
    q[o + 3] = -q[o + 3]!;
  }
}

/**
 * `out[oo…oo+3) = q ⊗ (vx, vy, vz) ⊗ q*` for the unit quaternion `q[qi…qi+4)`:
 * v + 2w (u × v) + 2 u × (u × v), with u = (x, y, z).
 */
export function rotateVector(
  q: ArrayLike<number>,
  qi: number,
  vx: number,
  vy: number,
  vz: number,
  out: Float64Array,
  oo: number,
): void {
  const w = q[qi]!,
    x = q[qi + 1]!,
    y = q[qi + 2]!,
    z = q[qi + 3]!;
  // t = 2 (u × v)
  const tx = 2 * (y * vz - z * vy);
  const ty = 2 * (z * vx - x * vz);
  const tz = 2 * (x * vy - y * vx);
  out[oo] = vx + w * tx + (y * tz - z * ty);
  out[oo + 1] = vy + w * ty + (z * tx - x * tz);
  out[oo + 2] = vz + w * tz + (x * ty - y * tx);
}

/** An Euler sequence as SciPy's `Rotation.from_euler` reads it: 'ZYX' intrinsic, 'xyz' extrinsic. */
export const EULER_SEQUENCE_PATTERN = /^(?:[XYZ]{3}|[xyz]{3})$/;

/** True when no two consecutive letters of the sequence name the same axis. */
export const validEulerSequence = (seq: string): boolean =>
  EULER_SEQUENCE_PATTERN.test(seq) &&
  seq[0]!.toLowerCase() !== seq[1]!.toLowerCase() &&
  seq[1]!.toLowerCase() !== seq[2]!.toLowerCase();

/** A compiled Euler sequence: axis index (0 = x) of each letter, and whether it is intrinsic. */
export interface EulerSequence {
  readonly axes: readonly [number, number, number];
  readonly intrinsic: boolean;
}

export function parseEulerSequence(seq: string): EulerSequence {
  const axis = (c: string): number => "xyz".indexOf(c.toLowerCase());
  return {
    axes: [axis(seq[0]!), axis(seq[1]!), axis(seq[2]!)],
    intrinsic: seq[0] === seq[0]!.toUpperCase(),
  };
}

const DEG = Math.PI / 180;

/** Sets `e[eo…eo+4)` to the rotation by `angle` radians about axis `axis` (0 = x, 1 = y, 2 = z). */
function elementary(axis: number, angle: number, e: Float64Array, eo: number): void {
  const h = angle / 2;
  e[eo] = Math.cos(h);
  e[eo + 1] = axis === 0 ? Math.sin(h) : 0;
  e[eo + 2] = axis === 1 ? Math.sin(h) : 0;
  e[eo + 3] = axis === 2 ? Math.sin(h) : 0;
}

/**
 * `out[o…o+4)` = the rotation of Euler angles `angles[ai…ai+3)` (degrees, in the order of the
 * sequence's letters). Intrinsic 'ABC' is R_A(a) · R_B(b) · R_C(c); extrinsic 'abc' is
 * R_c(c) · R_b(b) · R_a(a) (the first rotation about the fixed axis a is applied first).
 * `scratch` holds 8 values. Returns false when an angle is not finite.
 */
export function eulerInto(
  seq: EulerSequence,
  angles: ArrayLike<number>,
  ai: number,
  out: Float64Array,
  o: number,
  scratch: Float64Array,
): boolean {
  const a0 = angles[ai]!,
    a1 = angles[ai + 1]!,
    a2 = angles[ai + 2]!;
  if (!Number.isFinite(a0) || !Number.isFinite(a1) || !Number.isFinite(a2)) return false;
  const [x0, x1, x2] = seq.axes;
  if (seq.intrinsic) {
    elementary(x0, a0 * DEG, scratch, 0);
    elementary(x1, a1 * DEG, scratch, 4);
    multiply(scratch, 0, scratch, 4, scratch, 0);
    elementary(x2, a2 * DEG, scratch, 4);
    multiply(scratch, 0, scratch, 4, out, o);
  } else {
    elementary(x2, a2 * DEG, scratch, 0);
    elementary(x1, a1 * DEG, scratch, 4);
    multiply(scratch, 0, scratch, 4, scratch, 0);
    elementary(x0, a0 * DEG, scratch, 4);
    multiply(scratch, 0, scratch, 4, out, o);
  }
  return true;
}
