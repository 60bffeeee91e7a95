/**
 * The scope's spectrum (no DOM): Welch's power spectral density of the samples in view and their
 * median frequency, as scipy.signal.welch computes it with its defaults — Hann window (periodic),
 * segments of `nperseg` samples (256, or all of them when fewer) overlapping by half, each
 * detrended by its mean, one-sided, scaled to a density (units²/Hz), segments averaged.
 * The median frequency (fatigue: it falls as a muscle tires) splits the spectrum's power in two
 * equal halves: the first bin where the running sum of the PSD reaches half the total, moved back
 * linearly within that bin. Checked against scipy (fixtures/gen_spectrum.py).
 */

export interface Psd {
  /** Bin frequencies, Hz (0 … fs/2). */
  f: Float64Array;
  /** Power spectral density per bin, units²/Hz. */
  p: Float64Array;
}

export const NPERSEG = 256;

/** Scratch of one segment length: window, twiddles, buffers (reused between calls). */
interface Plan {
  n: number;
  window: Float64Array;
  /** Σ w² (for the density scale). */
  s2: number;
  re: Float64Array;
  im: Float64Array;
  cos: Float64Array;
  sin: Float64Array;
  pow2: boolean;
}

const plans = new Map<number, Plan>();

function plan(n: number): Plan {
  let p = plans.get(n);
  if (p) return p;
  const window = new Float64Array(n);
  let s2 = 0;
  for (let i = 0; i < n; i++) {
    // scipy's get_window("hann", n): periodic (fftbins=True).
    const w = 0.5 - 0.5 * Math.cos((2 * Math.PI * i) / n);
    window[i] = w;
    s2 += w * w;
  }
  const cos = new Float64Array(n);
  const sin = new Float64Array(n);
  for (let k = 0; k < n; k++) {
    cos[k] = Math.cos((2 * Math.PI * k) / n);
    sin[k] = Math.sin((2 * Math.PI * k) / n);
  }
  p = {
    n,
    window,
    s2,
    re: new Float64Array(n),
    im: new Float64Array(n),
    cos,
    sin,
    pow2: (n & (n - 1)) === 0,
  };
  if (plans.size > 8) plans.clear();
  plans.set(n, p);
  return p;
}

/** In-place radix-2 FFT of (re, im), n a power of two. */
function fft(pl: Plan): void {
  const { n, re, im, cos, sin } = pl;
  for (let i = 1, j = 0; i < n; i++) {
    let bit = n >> 1;
    for (; j & bit; bit >>= 1) j ^= bit;
    j ^= bit;
    if (i < j) {
      let t = re[i]!;
      re[i] = re[j]!;
      re[j] = t;
      t = im[i]!;
      im[i] = im[j]!;
      im[j] = t;
    }
  }
  for (let len = 2; len <= n; len <<= 1) {
    const step = n / len;
    const half = len >> 1;
    for (let i = 0; i < n; i += len) {
      for (let k = 0; k < half; k++) {
        const wr = cos[k * step]!;
        const wi = -sin[k * step]!;
        const a = i + k;
        const b = a + half;
        const xr = re[b]! * wr - im[b]! * wi;
        const xi = re[b]! * wi + im[b]! * wr;
        re[b] = re[a]! - xr;
        im[b] = im[a]! - xi;
        re[a] = re[a]! + xr;
        im[a] = im[a]! + xi;
      }
    }
  }
}

/** |X_k|² of the windowed segment in pl.re for k ≤ n/2, added into `acc`. */
function addPeriodogram(pl: Plan, acc: Float64Array): void {
  const { n, re, im } = pl;
  const bins = acc.length;
  if (pl.pow2) {
    im.fill(0);
    fft(pl);
    for (let k = 0; k < bins; k++) acc[k] = acc[k]! + re[k]! * re[k]! + im[k]! * im[k]!;
    return;
  }
  // A short window (fewer samples than NPERSEG) of any length: the plain DFT.
  for (let k = 0; k < bins; k++) {
    let sr = 0;
    let si = 0;
    for (let i = 0, m = 0; i < n; i++, m = (m + k) % n) {
      sr += re[i]! * pl.cos[m]!;
      si -= re[i]! * pl.sin[m]!;
    }
    acc[k] = acc[k]! + sr * sr + si * si;
  }
}

/**
 * Welch's PSD of the finite samples `x` at `fs` Hz (scipy.signal.welch defaults; nperseg =
 * min(NPERSEG, samples)). Null with fewer than 8 samples.
 */
export function welch(x: ArrayLike<number>, fs: number, nperseg = NPERSEG): Psd | null {
  const total = x.length;
  const n = Math.min(nperseg, total);
  if (n < 8 || !(fs > 0)) return null;
  const pl = plan(n);
  const step = n - Math.floor(n / 2);
  const bins = Math.floor(n / 2) + 1;
  const acc = new Float64Array(bins);
  let segments = 0;
  for (let start = 0; start + n <= total; start += step) {
    let mean = 0;
    for (let i = 0; i < n; i++) mean += x[start + i]!;
    mean /= n;
    for (let i = 0; i < n; i++) pl.re[i] = (x[start + i]! - mean) * pl.window[i]!;
    addPeriodogram(pl, acc);
    segments++;
  }
  const scale = 1 / (fs * pl.s2 * segments);
  const f = new Float64Array(bins);
  for (let k = 0; k < bins; k++) {
    f[k] = (k * fs) / n;
    // One-sided: every bin but DC (and Nyquist for an even n) counts twice.
    const twice = k > 0 && !(n % 2 === 0 && k === bins - 1);
    acc[k] = acc[k]! * scale * (twice ? 2 : 1);
  }
  return { f, p: acc };
}

/** The frequency below which half the power lies (NaN without power). */
export function medianFrequency(psd: Psd): number {
  const { f, p } = psd;
  let total = 0;
  for (let k = 0; k < p.length; k++) total += p[k]!;
  if (!(total > 0)) return NaN;
  const half = total / 2;
  let run = 0;
  for (let k = 0; k < p.length; k++) {
    const next = run + p[k]!;
    if (next >= half) {
      const df = k > 0 ? f[k]! - f[k - 1]! : f[1]! - f[0]!;
      return f[k]! - df * ((next - half) / p[k]!);
    }
    run = next;
  }
  return f[f.length - 1]!;
}

/**
 * The sample rate of time stamps `t` (s): samples per second over their span, NaN with fewer
 * than two or no span.
 */
export function sampleRate(t: ArrayLike<number>): number {
  const n = t.length;
  if (n < 2) return NaN;
  const span = t[n - 1]! - t[0]!;
  return span > 0 ? (n - 1) / span : NaN;
}
