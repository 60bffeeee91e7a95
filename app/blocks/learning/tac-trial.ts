/**
 * One TAC trial's geometry (tac.ts, tac-run.ts): the target and its tolerance, the path
 * travelled since the trial's start, when the control entered the target; and the results of
 * the finished trials (the summary).
 */

/** Euclidean distance between the first `D` values of `x` and `y`. */
export function distance(x: Float64Array, y: Float64Array, D: number): number {
  let s = 0;
  for (let i = 0; i < D; i++) {
    const d = x[i]! - y[i]!;
    s += d * d;
  }
  return Math.sqrt(s);
}

export class TacTrial {
  /** The active target. */
  readonly goal: Float64Array;
  /** Start of the trial, and the position there. */
  t0 = 0;
  private readonly startPos: Float64Array;
  /** The previous position, and the length of the path travelled since the start. */
  private readonly prev: Float64Array;
  private path = 0;
  /** Inside the target since `entryT`, when the path had length `entryPath`, at `entryPos`. */
  inside = false;
  entryT = 0;
  private entryPath = 0;
  private readonly entryPos: Float64Array;
  /** Distance to the target at the last position. */
  lastDistance = NaN;

  constructor(
    private readonly D: number,
    /** Per-DoF tolerance (live). */
    public tol: Float64Array,
    private readonly euclidean: boolean,
  ) {
    this.goal = new Float64Array(D);
    this.startPos = new Float64Array(D);
    this.prev = new Float64Array(D);
    this.entryPos = new Float64Array(D);
  }

  /** The trial starts at `time` from position `from` (towards `goal`). */
  begin(time: number, from: Float64Array): void {
    this.t0 = time;
    this.startPos.set(from);
    this.prev.set(from);
    this.path = 0;
    this.inside = false;
    this.lastDistance = distance(from, this.goal, this.D);
  }

  /** The control moved to `pos` at `time`: the path grows; returns whether it is inside. */
  move(time: number, pos: Float64Array): boolean {
    this.path += distance(pos, this.prev, this.D);
    this.prev.set(pos);
    this.lastDistance = distance(pos, this.goal, this.D);
    if (!this.isInside(pos)) {
      this.inside = false;
      return false;
    }
    if (!this.inside) {
      this.inside = true;
      this.entryT = time;
      this.entryPath = this.path;
      this.entryPos.set(pos);
    }
    return true;
  }

  /** Euclidean: Σ((x_i − t_i)/tol_i)² ≤ 1; box: |x_i − t_i| ≤ tol_i for every DoF. */
  private isInside(x: Float64Array): boolean {
    const { D, goal, tol } = this;
    if (this.euclidean) {
      let s = 0;
      for (let i = 0; i < D; i++) {
        const d = (x[i]! - goal[i]!) / tol[i]!;
        s += d * d;
      }
      return s <= 1;
    }
    for (let i = 0; i < D; i++) if (!(Math.abs(x[i]! - goal[i]!) <= tol[i]!)) return false;
    return true;
  }

  /** Straight line from the start to the entry that led to success, over the path until then. */
  efficiency(): number {
    return this.entryPath > 0 ? distance(this.entryPos, this.startPos, this.D) / this.entryPath : 1;
  }

  /** Distance from `pos` to the target. */
  distanceTo(pos: Float64Array): number {
    return distance(pos, this.goal, this.D);
  }
}

/** The results so far: trials, successes, sums over successful trials. */
export class TacScore {
  trials = 0;
  successes = 0;
  private sumTime = 0;
  private sumEfficiency = 0;

  clear(): void {
    this.trials = this.successes = 0;
    this.sumTime = this.sumEfficiency = 0;
  }

  add(success: boolean, completion: number, efficiency: number): void {
    this.trials++;
    if (success) {
      this.successes++;
      this.sumTime += completion;
      this.sumEfficiency += efficiency;
    }
  }

  /** Success rate, mean completion time and mean path efficiency (over successful trials). */
  summary(): string {
    const n = this.trials;
    const ok = this.successes;
    if (n === 0) return "no trials finished";
    const rate = Math.round((100 * ok) / n);
    const means =
      ok > 0
        ? `, mean completion ${(this.sumTime / ok).toFixed(2)} s, ` +
          `mean path efficiency ${(this.sumEfficiency / ok).toFixed(2)}`
        : "";
    return `${ok}/${n} succeeded (${rate} %)${means}`;
  }
}
