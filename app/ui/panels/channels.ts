/**
 * Pure helpers of the panels (no DOM): channel selections ("0-7, 12"), electrode grids, colours,
 * number formatting, autoscaling and smoothing.
 */

/** Channels plotted at once by default (more can be selected explicitly). */
export const DEFAULT_MAX_CHANNELS = 16;

/** "0-7, 12, 20-23" → sorted unique indices below `count`; an error sentence otherwise. */
export function parseChannelSelection(
  text: string,
  count: number,
): { ok: true; channels: number[] } | { ok: false; error: string } {
  const s = text.trim().toLowerCase();
  if (s === "" || s === "none") return { ok: true, channels: [] };
  if (s === "all" || s === "*") return { ok: true, channels: range(0, count) };
  const out = new Set<number>();
  for (const part of s.split(/[,;\s]+/).filter(Boolean)) {
    const m = /^(\d+)(?:\s*[-–:]\s*(\d+))?$/.exec(part);
    if (!m) return { ok: false, error: `'${part}' is not a channel or a range like 0-7` };
    const a = Number(m[1]);
    const b = m[2] !== undefined ? Number(m[2]) : a;
    if (b < a) return { ok: false, error: `'${part}': a range goes from low to high` };
    if (b >= count)
      return { ok: false, error: `channel ${b} does not exist (channels are 0–${count - 1})` };
    for (let k = a; k <= b; k++) out.add(k);
  }
  return { ok: true, channels: [...out].sort((x, y) => x - y) };
}

/** Sorted indices → "0-7, 12, 20-23". */
export function formatChannelSelection(channels: readonly number[]): string {
  const parts: string[] = [];
  let i = 0;
  while (i < channels.length) {
    let j = i;
    while (j + 1 < channels.length && channels[j + 1] === channels[j]! + 1) j++;
    parts.push(j > i ? `${channels[i]}-${channels[j]}` : `${channels[i]}`);
    i = j + 1;
  }
  return parts.join(", ");
}

export function range(a: number, b: number): number[] {
  const out: number[] = [];
  for (let k = a; k < b; k++) out.push(k);
  return out;
}

export function defaultChannels(count: number, max = DEFAULT_MAX_CHANNELS): number[] {
  return range(0, Math.min(count, max));
}

/**
 * A near-square electrode grid for n channels: an exact factorisation rows × cols with
 * cols / rows ≤ 2 when there is one (8 → 2 × 4, 32 → 4 × 8, 64 → 8 × 8, 256 → 16 × 16), else
 * ceil(√n) columns and as many rows as needed (7 → 3 × 3, one cell empty).
 */
export function inferGrid(n: number): { rows: number; cols: number } {
  if (n <= 0) return { rows: 1, cols: 1 };
  for (let r = Math.floor(Math.sqrt(n)); r >= 1; r--) {
    if (n % r === 0) {
      const c = n / r;
      if (c / r <= 2) return { rows: r, cols: c };
      break;
    }
  }
  const cols = Math.ceil(Math.sqrt(n));
  return { rows: Math.ceil(n / cols), cols };
}

/** Grids that hold n channels exactly (rows × cols = n), for the grid picker. */
export function gridChoices(n: number): { rows: number; cols: number }[] {
  const out: { rows: number; cols: number }[] = [];
  for (let r = 1; r <= n; r++) if (n % r === 0) out.push({ rows: r, cols: n / r });
  return out;
}

/** The cell of channel k on a grid: row-major (along rows first) or column-major. */
export function cellOf(
  k: number,
  cols: number,
  rows: number,
  columnMajor: boolean,
): [number, number] {
  return columnMajor ? [k % rows, Math.floor(k / rows)] : [Math.floor(k / cols), k % cols];
}

const TABLEAU = [
  "#1f77b4",
  "#ff7f0e",
  "#2ca02c",
  "#d62728",
  "#9467bd",
  "#8c564b",
  "#e377c2",
  "#17becf",
  "#bcbd22",
  "#7f7f7f",
];

/** A distinct colour per channel index (Tableau 10, then golden-angle hues). */
export function channelColor(k: number): string {
  if (k < TABLEAU.length) return TABLEAU[k]!;
  const hue = Math.round((k * 137.508) % 360);
  const light = 38 + ((k * 7) % 3) * 8;
  return `hsl(${hue} 70% ${light}%)`;
}

/** 4 significant digits, no exponent for ordinary magnitudes; ".inf"-style infinities. */
export function formatValue(v: number): string {
  if (Number.isNaN(v)) return "NaN";
  if (v === Infinity) return "∞";
  if (v === -Infinity) return "−∞";
  if (v === 0) return "0";
  const a = Math.abs(v);
  if (a >= 1e6 || a < 1e-4) return v.toExponential(3).replace("-", "−");
  const digits = Math.max(0, 3 - Math.floor(Math.log10(a)));
  return v.toFixed(Math.min(digits, 6)).replace("-", "−");
}

/** Channel names: the output's labels when the engine sends them, else the 0-based index. */
export function channelLabel(output: { labels?: unknown } | undefined, k: number): string {
  const labels = output?.labels;
  if (Array.isArray(labels) && typeof labels[k] === "string") return labels[k] as string;
  return String(k);
}

/**
 * An autoscaled range that widens at once and narrows slowly (time constant `tauS`), so a plot
 * does not jump with every frame. `update` takes the data range seen now and the seconds since
 * the previous update; non-finite input leaves it unchanged.
 */
export class StickyRange {
  lo = NaN;
  hi = NaN;
  constructor(
    readonly tauS = 2,
    readonly pad = 0.05,
  ) {}

  reset(): void {
    this.lo = NaN;
    this.hi = NaN;
  }

  update(min: number, max: number, dtS: number): [number, number] {
    if (Number.isFinite(min) && Number.isFinite(max)) {
      if (min === max) {
        const d = Math.abs(min) * 0.1 || 1;
        min -= d;
        max += d;
      }
      const span = max - min;
      const lo = min - span * this.pad;
      const hi = max + span * this.pad;
      if (!Number.isFinite(this.lo)) {
        this.lo = lo;
        this.hi = hi;
      } else {
        const k = 1 - Math.exp(-Math.max(0, dtS) / this.tauS);
        this.lo = lo < this.lo ? lo : this.lo + (lo - this.lo) * k;
        this.hi = hi > this.hi ? hi : this.hi + (hi - this.hi) * k;
      }
    }
    if (!Number.isFinite(this.lo)) return [-1, 1];
    return [this.lo, this.hi];
  }
}

/** How a panel turns a stream of values into the one it shows per channel. */
export type Reduce = "latest" | "smooth" | "envelope";

/**
 * Per-channel exponential smoothing by event time: `smooth` averages the values, `envelope`
 * their magnitudes (a moving mean |x|, what an activation map shows for raw EMG).
 */
export class Smoother {
  readonly out: Float64Array;
  private lastT = NaN;
  constructor(
    readonly channels: number,
    public mode: Reduce = "latest",
    public tauS = 0.2,
  ) {
    this.out = new Float64Array(channels).fill(NaN);
  }

  reset(): void {
    this.out.fill(NaN);
    this.lastT = NaN;
  }

  /** One event: values `v[offset + k * step]` for k < channels, at time t. */
  push(t: number, v: Float64Array, offset: number, step = 1): void {
    const n = this.channels;
    const o = this.out;
    const abs = this.mode === "envelope";
    if (this.mode === "latest" || !Number.isFinite(this.lastT)) {
      for (let k = 0; k < n; k++) {
        const x = v[offset + k * step]!;
        o[k] = abs ? Math.abs(x) : x;
      }
    } else {
      const dt = Math.max(0, t - this.lastT);
      const a = 1 - Math.exp(-dt / Math.max(1e-6, this.tauS));
      for (let k = 0; k < n; k++) {
        const raw = v[offset + k * step]!;
        const x = abs ? Math.abs(raw) : raw;
        const prev = o[k]!;
        o[k] = Number.isFinite(prev) ? prev + (x - prev) * a : x;
      }
    }
    this.lastT = t;
  }
}

/** Min and max of the finite values (NaN, NaN when none). */
export function finiteExtent(v: ArrayLike<number>, from = 0, to = v.length): [number, number] {
  let lo = Infinity;
  let hi = -Infinity;
  for (let i = from; i < to; i++) {
    const x = v[i]!;
    if (x - x !== 0) continue; // NaN and ±Infinity
    if (x < lo) lo = x;
    if (x > hi) hi = x;
  }
  return lo <= hi ? [lo, hi] : [NaN, NaN];
}

/** A tick label with as many decimals as the tick step needs ("0.25", "−1.5", "2000"). */
export function formatTick(v: number, step: number): string {
  if (!(step > 0) || !Number.isFinite(v)) return formatValue(v);
  const a = Math.abs(step);
  if (a >= 1e6 || a < 1e-6) return formatValue(v);
  let dec = Math.max(0, -Math.floor(Math.log10(a) + 1e-9));
  // Steps like 0.25 need one more decimal than their magnitude says.
  if (Math.abs(Math.round(a * 10 ** dec) - a * 10 ** dec) > 1e-6) dec++;
  const s = (Math.abs(v) < a * 1e-9 ? 0 : v).toFixed(Math.min(dec, 8));
  return s.replace("-", "−");
}

/** "nice" tick values between lo and hi (about `count`). */
export function niceTicks(lo: number, hi: number, count = 4): number[] {
  if (!(hi > lo)) return [lo];
  const raw = (hi - lo) / count;
  const mag = 10 ** Math.floor(Math.log10(raw));
  const step = [1, 2, 2.5, 5, 10].map((m) => m * mag).find((s) => s >= raw) ?? raw;
  const out: number[] = [];
  for (let v = Math.ceil(lo / step) * step; v <= hi + step * 1e-9; v += step)
    out.push(Math.abs(v) < step * 1e-9 ? 0 : v);
  return out;
}

const LITTLE_ENDIAN = new Uint8Array(new Uint32Array([1]).buffer)[0] === 1;

/** Viridis (matplotlib), 256 entries as packed RGBA for an ImageData. */
export const VIRIDIS: Uint32Array = (() => {
  // 9 control points of viridis; linear interpolation between them is within a few % of it.
  const pts = [
    [68, 1, 84],
    [71, 44, 122],
    [59, 81, 139],
    [44, 113, 142],
    [33, 144, 141],
    [39, 173, 129],
    [92, 200, 99],
    [170, 220, 50],
    [253, 231, 37],
  ];
  const lut = new Uint32Array(256);
  for (let i = 0; i < 256; i++) {
    const x = (i / 255) * (pts.length - 1);
    const j = Math.min(pts.length - 2, Math.floor(x));
    const f = x - j;
    const a = pts[j]!;
    const b = pts[j + 1]!;
    const r = Math.round(a[0]! + (b[0]! - a[0]!) * f);
    const g = Math.round(a[1]! + (b[1]! - a[1]!) * f);
    const bl = Math.round(a[2]! + (b[2]! - a[2]!) * f);
    // ImageData bytes are R, G, B, A in memory: pack the word for the platform's byte order.
    lut[i] = LITTLE_ENDIAN
      ? ((255 << 24) | (bl << 16) | (g << 8) | r) >>> 0
      : ((r << 24) | (g << 16) | (bl << 8) | 255) >>> 0;
  }
  return lut;
})();
