/**
 * A Buffer's rows (buffer.ts): [target…, data…] rows with their times, grown by doubling up to
 * MaxRows, and the labelled clusters they form (rows recorded with one target, between a start
 * and a stop or another target).
 */
import { formatVector, plural } from "../shared/text";

/** One labelled cluster: rows [start, start + rows) of the store, all with this target. */
export interface Cluster {
  target: Float64Array;
  start: number;
  rows: number;
}

export const sameValues = (a: ArrayLike<number>, b: ArrayLike<number>): boolean => {
  if (a.length !== b.length) return false;
  for (let i = 0; i < a.length; i++) if (a[i] !== b[i]) return false;
  return true;
};

export class BufferStore {
  /** Values per row, T + D. */
  readonly W: number;
  private values: Float64Array;
  private times: Float64Array;
  /** Rows stored. */
  rows = 0;
  /** Rows that did not fit (MaxRows), since the last clear. */
  dropped = 0;
  private readonly clusters: Cluster[] = [];
  /** The cluster being recorded, null when not recording. */
  current: Cluster | null = null;

  constructor(
    /** Values per target and per data row. */
    readonly T: number,
    readonly D: number,
    readonly maxRows: number,
  ) {
    this.W = T + D;
    this.values = new Float64Array(Math.min(maxRows, 256) * this.W);
    this.times = new Float64Array(Math.min(maxRows, 256));
  }

  /** Rows [from, to): their values, rows × W. */
  rowValues(from = 0, to = this.rows): Float64Array {
    return this.values.subarray(from * this.W, to * this.W);
  }

  /** Rows [from, to): their times. */
  rowTimes(from = 0, to = this.rows): Float64Array {
    return this.times.subarray(from, to);
  }

  /** True when a row with this target would go on recording into the current cluster. */
  recording(target: ArrayLike<number>): boolean {
    return this.current !== null && sameValues(this.current.target, target);
  }

  /** Starts recording a new cluster with `target` (close the current one first). */
  open(target: ArrayLike<number>): void {
    this.current = { target: Float64Array.from(target), start: this.rows, rows: 0 };
  }

  /** Closes the current cluster (kept only if it received rows); returns whether one was kept. */
  close(): boolean {
    const kept = this.current !== null && this.current.rows > 0;
    if (kept) this.clusters.push(this.current!);
    this.current = null;
    return kept;
  }

  /**
   * Appends up to `n` rows of the current cluster (its target, then the data event's D values,
   * times `t`); what does not fit under MaxRows is counted as dropped. Returns the rows taken.
   */
  append(t: Float64Array, v: Float64Array, n: number): number {
    const cur = this.current!;
    const room = this.maxRows - this.rows;
    const take = n < room ? n : room;
    this.dropped += n - take;
    if (take === 0) return 0;
    this.grow(this.rows + take);
    const { T, D, W, values, times, rows } = this;
    const tg = cur.target;
    for (let e = 0; e < take; e++) {
      const dst = (rows + e) * W;
      for (let k = 0; k < T; k++) values[dst + k] = tg[k]!;
      const src = e * D;
      for (let k = 0; k < D; k++) values[dst + T + k] = v[src + k]!;
      times[rows + e] = t[e]!;
    }
    this.rows += take;
    cur.rows += take;
    return take;
  }

  /** Drops every row; a cluster being recorded goes on, empty. */
  clear(): void {
    this.clusters.length = 0;
    this.rows = 0;
    this.dropped = 0;
    if (this.current) this.current = { target: this.current.target, start: 0, rows: 0 };
  }

  /** Drops every row and cluster, recording included. */
  reset(): void {
    this.clusters.length = 0;
    this.current = null;
    this.rows = 0;
    this.dropped = 0;
  }

  /** "2 clusters, 40 rows", or "empty". */
  summary(): string {
    const n = this.clusters.length + (this.current !== null && this.current.rows > 0 ? 1 : 0);
    if (n === 0) return "empty";
    return `${plural(n, "cluster")}, ${plural(this.rows, "row")}`;
  }

  /** "[1, 0]: 2 clusters, 40 rows; [0, 1]: …", per distinct target in order of appearance. */
  perTarget(): string {
    const groups: { target: Float64Array; clusters: number; rows: number }[] = [];
    const cur = this.current;
    const all = cur && cur.rows > 0 ? [...this.clusters, cur] : this.clusters;
    for (const c of all) {
      const g = groups.find((x) => sameValues(x.target, c.target));
      if (g) {
        g.clusters++;
        g.rows += c.rows;
      } else groups.push({ target: c.target, clusters: 1, rows: c.rows });
    }
    return groups
      .map(
        (g) =>
          `${formatVector(g.target)}: ${plural(g.clusters, "cluster")}, ${plural(g.rows, "row")}`,
      )
      .join("; ");
  }

  /** One CSV line `target…,data…` per row (no header), as MOSAIC's save button wrote. */
  csv(): string {
    const { rows, W, values } = this;
    const lines: string[] = new Array<string>(rows);
    const parts: string[] = new Array<string>(W);
    for (let r = 0; r < rows; r++) {
      const off = r * W;
      for (let k = 0; k < W; k++) parts[k] = String(values[off + k]);
      lines[r] = parts.join(",");
    }
    return rows > 0 ? lines.join("\n") + "\n" : "";
  }

  /** Room for `need` rows: doubles the capacity until it fits (at most MaxRows). */
  private grow(need: number): void {
    let cap = this.times.length;
    if (need <= cap) return;
    while (cap < need) cap *= 2;
    cap = Math.min(cap, this.maxRows);
    const v = new Float64Array(cap * this.W);
    v.set(this.rowValues());
    const t = new Float64Array(cap);
    t.set(this.rowTimes());
    this.values = v;
    this.times = t;
  }
}
