/**
 * The last minute of a block's telemetry (no DOM): status, rate, compute time and the largest
 * delivery delay per telemetry message (20 Hz), in fixed rings — what the Status tab draws as a
 * strip and curves and summarises.
 */
import type { Status } from "../../engine/runtime/status";

export const STATUS_ORDER: readonly Status[] = ["ontime", "stumbling", "lagging", "idle"];
const CODE: Record<Status, number> = { ontime: 0, stumbling: 1, lagging: 2, idle: 3 };

export interface HistorySummary {
  /** Share of the time in each status over the history (0–1). */
  fraction: Record<Status, number>;
  computeMeanMs: number;
  computeMaxMs: number;
  rateMin: number;
  rateMax: number;
  rateMean: number;
  /** Largest delivery delay of the history, ms. */
  delayMaxMs: number;
  samples: number;
}

export class StatusHistory {
  readonly cap: number;
  readonly t: Float64Array;
  readonly status: Uint8Array;
  readonly rate: Float64Array;
  readonly computeMean: Float64Array;
  readonly computeMax: Float64Array;
  /** Largest delivery delay of each telemetry window, ms. */
  readonly delayMax: Float64Array;
  private head = 0;
  count = 0;

  constructor(
    readonly seconds = 60,
    telemetryHz = 20,
  ) {
    this.cap = Math.ceil(seconds * telemetryHz);
    this.t = new Float64Array(this.cap);
    this.status = new Uint8Array(this.cap);
    this.rate = new Float64Array(this.cap);
    this.computeMean = new Float64Array(this.cap);
    this.computeMax = new Float64Array(this.cap);
    this.delayMax = new Float64Array(this.cap);
  }

  clear(): void {
    this.head = 0;
    this.count = 0;
  }

  push(
    t: number,
    status: Status,
    rate: number,
    computeMeanMs: number,
    computeMaxMs: number,
    delayMaxMs = 0,
  ): void {
    // A clock that went back (a new run) starts the history again.
    if (this.count && t < this.newestT - 1) this.clear();
    const i = this.head;
    this.t[i] = t;
    this.status[i] = CODE[status] ?? 3;
    this.rate[i] = rate;
    this.computeMean[i] = computeMeanMs;
    this.computeMax[i] = computeMaxMs;
    this.delayMax[i] = delayMaxMs;
    this.head = (i + 1) % this.cap;
    if (this.count < this.cap) this.count++;
  }

  get newestT(): number {
    return this.count ? this.t[(this.head - 1 + this.cap) % this.cap]! : NaN;
  }

  /** Oldest to newest, within the last `seconds`. */
  forEach(
    fn: (
      t: number,
      status: Status,
      rate: number,
      computeMeanMs: number,
      computeMaxMs: number,
      delayMaxMs: number,
    ) => void,
  ): void {
    const from = this.newestT - this.seconds;
    for (let k = 0; k < this.count; k++) {
      const i = (this.head - this.count + k + this.cap) % this.cap;
      const t = this.t[i]!;
      if (t < from) continue;
      fn(
        t,
        STATUS_ORDER[this.status[i]!]!,
        this.rate[i]!,
        this.computeMean[i]!,
        this.computeMax[i]!,
        this.delayMax[i]!,
      );
    }
  }

  summary(): HistorySummary {
    const counts: Record<Status, number> = { ontime: 0, stumbling: 0, lagging: 0, idle: 0 };
    let n = 0;
    let cSum = 0;
    let cMax = 0;
    let rMin = Infinity;
    let rMax = -Infinity;
    let rSum = 0;
    let dMax = 0;
    this.forEach((_t, s, rate, cm, cx, dx) => {
      counts[s]++;
      n++;
      cSum += cm;
      if (cx > cMax) cMax = cx;
      if (rate < rMin) rMin = rate;
      if (rate > rMax) rMax = rate;
      rSum += rate;
      if (dx > dMax) dMax = dx;
    });
    const fraction = { ...counts };
    for (const s of STATUS_ORDER) fraction[s] = n ? counts[s] / n : 0;
    return {
      fraction,
      computeMeanMs: n ? cSum / n : 0,
      computeMaxMs: cMax,
      rateMin: n ? rMin : 0,
      rateMax: n ? rMax : 0,
      rateMean: n ? rSum / n : 0,
      delayMaxMs: dMax,
      samples: n,
    };
  }
}
