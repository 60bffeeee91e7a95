/**
 * A compact histogram of delays in seconds (delivery delay: processing time − event timestamp),
 * log-linear like HDR histograms: 1 µs bins below 64 µs, then 32 bins per power of two (≤ 3.1 %
 * relative error) up to about 68 s. 672 bins, no allocation after construction, O(1) `add`.
 */

const LINEAR_US = 64;
const SUB_BITS = 5;
const SUB = 1 << SUB_BITS;
/** Octaves above the linear range: 64 µs · 2^20 ≈ 67 s. */
const OCTAVES = 20;
const BINS = LINEAR_US + OCTAVES * SUB;

/** Bin index of a delay in µs (negative delays, e.g. clock rounding, go to bin 0). */
function binOf(us: number): number {
  if (!(us > 0)) return 0;
  if (us < LINEAR_US) return Math.floor(us);
  const v = Math.floor(us);
  const octave = 31 - Math.clz32(v) - 6; // 0 for [64, 128)
  if (octave >= OCTAVES) return BINS - 1;
  const sub = (v >>> (octave + 6 - SUB_BITS)) - SUB; // 0 … SUB − 1
  return LINEAR_US + octave * SUB + sub;
}

/** Upper edge of a bin, µs (what a quantile reports: never optimistic; the last bin is open). */
function upperOf(bin: number): number {
  if (bin === BINS - 1) return Infinity;
  if (bin < LINEAR_US) return bin + 1;
  const octave = Math.floor((bin - LINEAR_US) / SUB);
  const sub = (bin - LINEAR_US) % SUB;
  const width = 1 << (octave + 6 - SUB_BITS);
  return (SUB + sub + 1) * width;
}

export class DelayHistogram {
  private readonly bins = new Uint32Array(BINS);
  count = 0;
  /** Largest delay recorded, s (exact, not binned). */
  max = 0;
  /** `p50` and `p99` as of `summarized` delays (recomputed only when more were added). */
  private p50s = NaN;
  private p99s = NaN;
  private summarized = 0;

  /** Records a delay of `s` seconds. */
  add(s: number): void {
    this.bins[binOf(s * 1e6)]!++;
    this.count++;
    if (s > this.max) this.max = s;
  }

  /** The q-quantile (q in [0, 1]) in seconds, from the bin's upper edge (NaN when empty). */
  quantile(q: number): number {
    if (this.count === 0) return NaN;
    const target = Math.max(1, Math.ceil(q * this.count));
    let acc = 0;
    const bins = this.bins;
    for (let i = 0; i < BINS; i++) {
      acc += bins[i]!;
      if (acc >= target) return Math.min(upperOf(i) / 1e6, this.max);
    }
    return this.max;
  }

  /** The median, s (NaN when empty); cached until more delays are added. */
  get p50(): number {
    this.summarize();
    return this.p50s;
  }

  /** The 99th percentile, s (NaN when empty); cached until more delays are added. */
  get p99(): number {
    this.summarize();
    return this.p99s;
  }

  reset(): void {
    this.bins.fill(0);
    this.count = 0;
    this.max = 0;
    this.p50s = NaN;
    this.p99s = NaN;
    this.summarized = 0;
  }

  /** Both quantiles in one pass over the bins. */
  private summarize(): void {
    if (this.summarized === this.count) return;
    this.summarized = this.count;
    const n = this.count;
    const t50 = Math.max(1, Math.ceil(0.5 * n));
    const t99 = Math.max(1, Math.ceil(0.99 * n));
    let acc = 0;
    let p50 = NaN;
    const bins = this.bins;
    for (let i = 0; i < BINS; i++) {
      const c = bins[i]!;
      if (c === 0) continue;
      acc += c;
      if (p50 !== p50 && acc >= t50) p50 = Math.min(upperOf(i) / 1e6, this.max);
      if (acc >= t99) {
        this.p50s = p50;
        this.p99s = Math.min(upperOf(i) / 1e6, this.max);
        return;
      }
    }
    this.p50s = p50;
    this.p99s = this.max;
  }
}
