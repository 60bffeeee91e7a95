/**
 * FilePlayer: one player of a recording, its state in one place. With a timer input it emits a
 * row per tick (`process`); without, it paces the rows at their original timing with one-shot
 * wake-ups (`ctx.at`), batched like timer ticks. Pause, resume, seek, restart, Speed and Loop
 * move its position and its time base.
 */
import { vectorShape, type BlockContext, type Frame, type OutputPort } from "../../engine";
import { TextThrottle } from "../shared/text";
import type { FilePlayerParams } from "./file-player-rows";
import { playPosition, type PlayPosition } from "./file-player-position";
import { fmtSeconds, rowAt, SEEK_USAGE, seekRefusal, seekSeconds } from "./file-player-seek";
import { statusText, type PlayState } from "./file-player-status";
import { loopSpan, speedProblem, type PlayTiming } from "./file-player-timing";
import type { RowSource } from "./row-source";

/** Most rows one wake-up of a self-timed player waits for (a batching interval rarely holds more). */
const MAX_BATCH_ROWS = 65536;

/** A row of a pass in a scan ahead: [row, pass]. */
type RowOfPass = [number, number];

/**
 * A player's state and what changes it. The PlayState fields are public for its status text
 * (statusText); only the player's own methods change them.
 */
export class PlayerRun implements PlayState {
  row = 0;
  loops = 0;
  done = false;
  paused = false;
  failed: string | undefined;
  readonly file: string;
  private started = false;
  /** When the first row of pass 0 is (or would have been) due, s (original timing). */
  private base = NaN;
  private pausedAt = NaN;
  private stoppedAt = NaN;
  private speed: number;
  private loop: boolean;
  private readonly t0: number;
  private readonly median: number;
  private span: number;
  private readonly width: number;
  private readonly out: OutputPort;
  private readonly position: PlayPosition;
  private readonly throttle = new TextThrottle();

  /** Declares the outputs (`out`, then `position`) and shows the first status text. */
  constructor(
    private readonly ctx: BlockContext,
    p: FilePlayerParams,
    private readonly timed: boolean,
    private readonly src: RowSource,
    timing: PlayTiming,
  ) {
    this.file = p.File;
    this.t0 = timing.t0;
    this.median = timing.median;
    this.span = timing.span;
    this.speed = p.Speed;
    this.loop = p.Loop;
    this.width = src.width;
    this.out = ctx.output(vectorShape(src.width), undefined, {
      ...(src.labels ? { labels: src.labels } : {}),
      ...(src.unit ? { unit: src.unit } : {}),
    });
    this.position = playPosition(ctx, src);
    this.describe();
  }

  // ---- lifecycle ----------------------------------------------------------------------------

  start(): void {
    this.started = true;
    if (!this.timed) {
      // The first start plays from the pipeline start; after a stop, the remaining rows
      // move by the time it was stopped (as after pause/resume), so none bursts out late.
      if (Number.isNaN(this.base)) this.base = this.ctx.startTime;
      else if (!this.paused && !Number.isNaN(this.stoppedAt)) {
        this.base += this.ctx.now() - this.stoppedAt;
      }
    }
    this.schedule();
  }

  stop(): void {
    this.started = false;
    this.stoppedAt = this.ctx.now();
  }

  /** With a timer input: one row per tick, stamped with the tick's time. */
  process(f: Frame): void {
    if (this.paused || this.done) return;
    const want = f.n;
    if (want === 0) return;
    const n = this.loop ? want : Math.min(want, this.src.fill(this.row + want) - this.row);
    if (n <= 0) {
      this.finish();
      return;
    }
    if (!this.emitRows(n, f.t)) this.finish();
    else if (this.throttle.due(f.t[n - 1]!)) this.describe();
  }

  /** As a fresh start: back to the first row, the position not announced (no one moved it). */
  reset(): void {
    this.paused = false;
    this.rewind(false);
  }

  dispose(): void {
    this.src.close();
  }

  // ---- rows ---------------------------------------------------------------------------------

  private has(r: number): boolean {
    return this.src.fill(r + 1) > r;
  }

  /**
   * Emits `n` rows from the current one in one frame (and their positions), stamped with `stamps`
   * (a timer's ticks) or else with their due times; returns false when playback ended within them.
   */
  private emitRows(n: number, stamps: Float64Array | undefined): boolean {
    const o = this.out.frame(n);
    const ov = o.v;
    const po = this.position.frame(n);
    let more = true;
    for (let e = 0; e < n; e++) {
      const t = stamps ? stamps[e]! : this.dueTime(this.row, this.loops);
      o.t[e] = t;
      this.src.copy(this.row, ov, e * this.width);
      if (po) this.position.put(po, e, t, this.row);
      if (!this.advance()) {
        more = false;
        o.n = e + 1;
        break;
      }
    }
    this.src.release(this.row);
    this.out.emit(o);
    if (po) this.position.emit(po, o.n);
    return more;
  }

  /** Advances past the row just played; returns false when playback ended. */
  private advance(): boolean {
    this.row++;
    if (this.has(this.row)) return true;
    if (this.src.error !== undefined) return false;
    if (this.loop) {
      this.src.rewind();
      this.row = 0;
      this.loops++;
      return this.has(0);
    }
    return false;
  }

  private finish(): void {
    this.done = true;
    if (this.src.error !== undefined && this.failed === undefined) {
      this.failed = this.src.error;
      this.ctx.error(`stopped playing: ${this.failed}`);
    }
    this.describe();
    this.ctx.finish();
  }

  private describe(): void {
    this.ctx.setText(statusText(this, this.src.total));
  }

  // ---- original timing ------------------------------------------------------------------------

  private dueTime(r: number, l: number): number {
    return this.base + (this.src.time(r) - this.t0 + l * this.span) / this.speed;
  }

  /** The row after `r` of pass `l` in a scan ahead, or undefined where the scan stops. */
  private after(r: number, l: number): RowOfPass | undefined {
    if (this.has(r + 1)) return [r + 1, l];
    // A streamed file's next pass is read after this one: scans stop at its end.
    if (!this.loop || !this.src.whole) return undefined;
    return [0, l + 1];
  }

  /** How many rows from the current one are due by `t`. */
  private countDue(t: number): number {
    let n = 0;
    let at: RowOfPass | undefined = [this.row, this.loops];
    while (at && this.dueTime(at[0], at[1]) <= t) {
      n++;
      at = this.after(at[0], at[1]);
    }
    return n;
  }

  /**
   * When the worker must wake at the latest: the due time of the last row within the batching
   * interval of the next one (rows then go out together, as a device sends packets; DESIGN.md
   * §3). From the next row's due time on, the rows due go out whenever the worker is awake
   * anyway, in the same steps as timer ticks of the same times (so a replay meets the other
   * inputs of a block as the recorded run did).
   */
  private nextWake(): number {
    const first = this.dueTime(this.row, this.loops);
    const batch = this.ctx.batching;
    if (!(batch > 0)) return first;
    let last = first;
    let at: RowOfPass | undefined = [this.row, this.loops];
    for (let k = 0; k < MAX_BATCH_ROWS; k++) {
      at = this.after(at[0], at[1]);
      if (!at) break;
      const d = this.dueTime(at[0], at[1]);
      if (d > first + batch) break;
      last = d;
    }
    return last;
  }

  private arm(): void {
    this.ctx.at(this.dueTime(this.row, this.loops), this.onTime, this.nextWake());
  }

  /** A wake-up: the rows due by now go out in one frame, stamped with their own times. */
  private readonly onTime = (): void => {
    if (this.paused || this.done) return;
    const t = this.ctx.now();
    for (;;) {
      const n = this.countDue(t);
      if (n > 0 && !this.emitRows(n, undefined)) {
        this.finish();
        return;
      }
      // A streamed file's next pass (Loop) begins after this frame: its due rows go in the next.
      if (n > 0 && !this.src.whole && this.row === 0 && this.dueTime(0, this.loops) <= t) continue;
      break;
    }
    if (this.throttle.due(t)) this.describe();
    this.arm();
  };

  private schedule(): void {
    if (this.timed || this.paused || this.done || !this.started) return;
    this.arm();
  }

  // ---- controls -----------------------------------------------------------------------------

  /** The `seek` action: play on from the row at `arg` seconds (whole files, timed by their rows). */
  seek(arg: unknown): string {
    const s = seekSeconds(arg);
    if (s === undefined) return SEEK_USAGE;
    const refused = seekRefusal(this.src);
    if (refused !== undefined) return refused;
    const r = rowAt(this.src, s);
    if (r === undefined) {
      const lasts = fmtSeconds(this.src.lastTime() - this.src.time(0));
      return `the recording lasts ${lasts} s: nothing at ${s} s`;
    }
    this.row = r;
    this.done = false;
    if (!this.timed && this.started) {
      this.base =
        this.ctx.now() - (this.src.time(r) - this.t0 + this.loops * this.span) / this.speed;
    }
    this.moved();
    return `at ${fmtSeconds(this.src.time(r) - this.src.time(0))} s (row ${r + 1})`;
  }

  /** The `restart` action: play again from the first row. */
  restart(): string {
    this.paused = false;
    this.rewind();
    return `restarted ${this.file}`;
  }

  /** The `pause` action: stop emitting rows until resumed. */
  pause(): string {
    if (this.paused || this.done) return this.done ? "already finished" : "already paused";
    this.paused = true;
    this.pausedAt = this.ctx.now();
    this.describe();
    return `paused at row ${this.row}`;
  }

  /** The `resume` action: the remaining rows move by the time it was paused. */
  resume(): string {
    if (!this.paused) return "not paused";
    this.paused = false;
    if (!this.timed && !Number.isNaN(this.base)) this.base += this.ctx.now() - this.pausedAt;
    this.describe();
    this.schedule();
    return `resumed at row ${this.row}`;
  }

  /** Speed while playing: the position stays where it is, the rows after it come faster. */
  setSpeed(v: number): void {
    if (!this.timed) {
      const problem = speedProblem(v, this.median, this.file);
      if (problem !== undefined) throw new Error(problem);
      const anchor = this.paused ? this.pausedAt : this.started ? this.ctx.now() : this.stoppedAt;
      if (!Number.isNaN(this.base) && !Number.isNaN(anchor)) {
        this.base = anchor - ((anchor - this.base) * this.speed) / v;
      }
      // The rate it is judged by follows (unless the file declares one).
      if (this.ctx.declaredRate === undefined) this.ctx.setDesiredRate(v / this.median);
    }
    this.speed = v;
    this.schedule();
  }

  /** Loop while playing: the end of the file starts it again (or, turned off, ends it). */
  setLoop(v: boolean): void {
    if (v && !this.timed && this.span === 0) this.span = loopSpan(this.src, this.t0, this.median);
    this.loop = v;
    if (!v) this.schedule();
  }

  /** Back to the first row of the first pass (`announce`: the position goes out at once). */
  private rewind(announce = true): void {
    if (this.row !== 0 || this.loops !== 0 || this.done) this.src.rewind();
    this.row = 0;
    this.loops = 0;
    this.done = false;
    this.failed = undefined;
    this.throttle.reset();
    if (!this.timed && this.started) this.base = this.ctx.now();
    if (announce) this.moved();
    else {
      this.describe();
      this.schedule();
    }
  }

  /** After a seek or a rewind: the text, the next wake-up and the position, at once. */
  private moved(): void {
    this.describe();
    this.schedule();
    this.position.now(this.row);
  }
}
