/**
 * The data-record duration of an EDF+/BDF+ file. Every signal holds a whole number of samples per
 * record (edf.html: "samples in each data record"), and the duration is written in 8 ASCII
 * characters, so it is a decimal with at most 6 decimals. The rule:
 *
 * 1. Each rate is read as the fraction p/q with the smallest denominator within half a unit of
 *    its third decimal (continued fractions), so a rate written with 3 decimals is the device's: the Trigno's
 *    1925.926 Hz (26 samples / 13.5 ms) is 52000/27 Hz, its 148.148 Hz 4000/27 Hz. The file's rate
 *    is that fraction.
 * 2. The shortest duration that fits every rate is E = lcm(q)/gcd(p) seconds, made a decimal of at
 *    most 6 decimals (the smallest multiple of it that is one): 0.027 s for 1925.926 Hz (52
 *    samples), 0.0005 s for 2000 Hz, 0.015625 s for 2048 Hz.
 * 3. The record is the longest multiple of E that is at most `target` (0.5 s: a kill loses less
 *    than one record) and keeps a record within 61 440 bytes (the spec's preference), at least E;
 *    E longer than 60 s is an error.
 */

import { PREFERRED_RECORD_BYTES } from "./edf-writer";

/** How far the fraction that stands for a rate may be from it: half the third decimal. */
const RATE_TOLERANCE_HZ = 5e-4;
const MAX_DENOMINATOR = 1_000_000;
export const MAX_RECORD_SECONDS = 60;
export const DEFAULT_TARGET_SECONDS = 0.5;

const gcd = (a: number, b: number): number => {
  let x = Math.abs(a);
  let y = Math.abs(b);
  while (y !== 0) [x, y] = [y, x % y];
  return x;
};

/**
 * The simplest fraction p/q (smallest q) within half a unit of the rate's third decimal (and
 * 0.01 % of it), the way devices write their rates: 1925.926 → 52000/27, 148.148 → 4000/27,
 * 2000 → 2000/1. Null when the rate is not positive and finite or the fraction is too large.
 */
export function rateFraction(rate: number): { p: number; q: number } | null {
  if (!(rate > 0) || !Number.isFinite(rate)) return null;
  const tol = Math.min(RATE_TOLERANCE_HZ, rate * 1e-4);
  const f = simplestIn(rate - tol, rate + tol);
  if (f === null || f.q > MAX_DENOMINATOR || !Number.isSafeInteger(f.p)) return null;
  return f;
}

/** The fraction with the smallest denominator in [lo, hi] (0 < lo < hi), by continued fractions. */
function simplestIn(lo: number, hi: number): { p: number; q: number } | null {
  const terms: number[] = [];
  for (let i = 0; i < 48; i++) {
    const c = Math.ceil(lo);
    if (c <= hi) {
      terms.push(c);
      break;
    }
    const a = Math.floor(lo);
    terms.push(a);
    [lo, hi] = [1 / (hi - a), 1 / (lo - a)];
  }
  if (terms.length === 0 || !(Math.ceil(lo) <= hi)) return null;
  let p = terms[terms.length - 1]!;
  let q = 1;
  for (let i = terms.length - 2; i >= 0; i--) [p, q] = [terms[i]! * p + q, p];
  return { p, q };
}

export interface RecordDurationInput {
  /** Samples per second. */
  rate: number;
  /** Bytes one sample of this signal takes in a record (channels × bytes per value). */
  bytesPerSample: number;
  /** For messages: the input's name. */
  name: string;
}

export interface RecordDuration {
  /** Microseconds (exact). */
  us: number;
  /** As written in the header ("0.027"). */
  text: string;
  /** Samples per record of each input, in order. */
  samples: number[];
}

/** Whole microseconds of the shortest duration that fits every rate (step 2), or an error text. */
function shortestFit(inputs: readonly RecordDurationInput[]): number | string {
  let L = 1; // lcm of the q
  let G = 0; // gcd of the p
  for (const i of inputs) {
    const f = rateFraction(i.rate);
    if (f === null) {
      return `${i.name}'s rate ${i.rate} Hz is not a ratio of whole numbers (denominator at most 10^6)`;
    }
    L = (L / gcd(L, f.q)) * f.q;
    G = gcd(G, f.p);
    if (!Number.isSafeInteger(L)) return "the rates have no common record duration";
  }
  // E = L / G seconds; in microseconds with at most 6 decimals: a multiple j0 = G / gcd(G, 10^6).
  const j0 = G / gcd(G, 1_000_000);
  const us = (j0 * L * 1_000_000) / G;
  if (!Number.isSafeInteger(us)) return "the rates have no common record duration";
  return us;
}

/** The duration text (≤ 8 characters, exact), or null when it does not fit. */
export function durationText(us: number): string | null {
  const s = Math.floor(us / 1e6);
  const f = us - s * 1e6;
  const text = f === 0 ? String(s) : `${s}.${String(f).padStart(6, "0").replace(/0+$/, "")}`;
  return text.length <= 8 ? text : null;
}

/** Samples per record of each input: p·us / (q·10^6), whole for a duration that fits. */
const samplesOf = (inputs: readonly RecordDurationInput[], us: number): number[] =>
  inputs.map((i) => {
    const f = rateFraction(i.rate)!;
    return Math.round((f.p * us) / (f.q * 1e6));
  });

/**
 * The record duration by the rule above; `fixed` (seconds) is checked instead of chosen. Throws
 * with a message naming the input whose rate does not fit.
 */
export function chooseRecordDuration(
  inputs: readonly RecordDurationInput[],
  opts: { fixed?: number; target?: number; annotationBytes?: number } = {},
): RecordDuration {
  const e = shortestFit(inputs);
  if (typeof e === "string") throw new Error(e);
  if (opts.fixed !== undefined) return checkFixed(inputs, opts.fixed, e);
  if (e > MAX_RECORD_SECONDS * 1e6) {
    throw new Error(
      `no record duration of at most ${MAX_RECORD_SECONDS} s holds a whole number of samples of every ` +
        `input (${inputs.map((i) => `${i.name} ${i.rate} Hz`).join(", ")}; the shortest is ${e / 1e6} s): ` +
        "record inputs of such rates in separate files",
    );
  }
  const target = (opts.target ?? DEFAULT_TARGET_SECONDS) * 1e6;
  const annot = opts.annotationBytes ?? 0;
  const bytesPerE = samplesOf(inputs, e).reduce((a, n, k) => a + n * inputs[k]!.bytesPerSample, 0);
  let k = Math.max(1, Math.floor(target / e));
  while (k > 1 && k * bytesPerE + annot > PREFERRED_RECORD_BYTES) k--;
  let us = k * e;
  // A multiple of E past 10 s may need more characters than the field holds: take the next one.
  while (durationText(us) === null && us <= MAX_RECORD_SECONDS * 1e6) us += e;
  const text = durationText(us);
  if (text === null) throw new Error("no record duration fits the header's 8 characters");
  return { us, text, samples: samplesOf(inputs, us) };
}

function checkFixed(
  inputs: readonly RecordDurationInput[],
  seconds: number,
  e: number,
): RecordDuration {
  const us = Math.round(seconds * 1e6);
  const text = durationText(us);
  if (text === null || Math.abs(us - seconds * 1e6) > 1e-3 || us <= 0) {
    throw new Error(`${seconds} s is not a duration of at most 8 characters with 6 decimals`);
  }
  if (us > MAX_RECORD_SECONDS * 1e6) throw new Error(`at most ${MAX_RECORD_SECONDS} s`);
  for (const i of inputs) {
    const n = (i.rate * us) / 1e6;
    const f = rateFraction(i.rate)!;
    // Exact test on the fraction: p·us / (q·10^6) whole.
    if ((BigInt(f.p) * BigInt(us)) % (BigInt(f.q) * 1_000_000n) !== 0n) {
      throw new Error(
        `${i.name} at ${i.rate} Hz gives ${n.toFixed(3)} samples per ${text} s record, not a whole ` +
          `number: use a multiple of ${e / 1e6} s (or leave RecordDuration out)`,
      );
    }
  }
  return { us, text, samples: samplesOf(inputs, us) };
}
