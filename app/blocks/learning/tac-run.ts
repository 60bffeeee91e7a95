/**
 * One TAC's run (tac.ts): the trials (from Targets, from the target input, or from a named
 * Stimulus's capture phases), hold and time-limit timing, scoring (tac-trial.ts), the `trial` and
 * `target` outputs, the status text and the actions.
 */
import {
  vectorShape,
  type BlockAction,
  type BlockContext,
  type BlockInstance,
  type Frame,
  type OutputPort,
} from "../../engine";
import { lookup } from "../shared/named";
import { plural, TextThrottle } from "../shared/text";
import type { StimulusTriggers } from "./stimulus";
import type { PerDof, TacPorts } from "./tac-setup";
import { TacScore, TacTrial } from "./tac-trial";
import { seconds } from "./trigger";

export interface TacOptions {
  /** The targets of `Targets` (trials in that order when there is no target input). */
  list: Float64Array[];
  tolerance: Float64Array;
  euclidean: boolean;
  dwell: number;
  timeLimit: number;
  pause: number;
  autostart: boolean;
  /** MOSAIC's form: the Stimulus whose capture phases are the trials. */
  stimulus: string | undefined;
}

export class TacRun {
  private readonly D: number;
  private readonly controlPort: number;
  private readonly targetPort: number;
  private readonly perDof: PerDof;
  private readonly list: Float64Array[];
  /** Trials of Targets (0 with a target input). */
  private readonly total: number;
  /** Trials start from `list` (no target input, no Stimulus). */
  private readonly listMode: boolean;
  private readonly stimulusName: string | undefined;
  private readonly autostart: boolean;
  private dwell: number;
  private timeLimit: number;
  private pause: number;
  private readonly trialOut: OutputPort;
  private readonly targetOut: OutputPort;
  private readonly trial: TacTrial;
  private readonly score = new TacScore();
  private readonly throttle = new TextThrottle(0.1);

  private running = false;
  private started = false;
  /** Index of the next trial (Targets mode) or of the current/next one (input mode). */
  private k = 0;
  private inTrial = false;
  private nextStart = -Infinity;
  /** Input mode: a target that arrived before any control position; the trial starts at the next control event. */
  private pending = false;
  private pendingT = 0;
  /** Input mode: the last target received (NaN after a stop), so that a repeated one changes nothing. */
  private readonly lastTarget: Float64Array;
  /** The last control position. */
  private readonly pos: Float64Array;
  private havePos = false;
  /** MOSAIC's form: the named Stimulus read, and the end of its subscription. */
  private stim: StimulusTriggers | undefined;
  private unlisten: (() => void) | undefined;

  constructor(
    private readonly ctx: BlockContext,
    ports: TacPorts,
    o: TacOptions,
  ) {
    const D = ports.D;
    this.D = D;
    this.controlPort = ports.control;
    this.targetPort = ports.target;
    this.perDof = ports.perDof;
    this.list = o.list;
    this.total = ports.hasTargetInput ? 0 : o.list.length;
    this.listMode = !ports.hasTargetInput && o.stimulus === undefined;
    this.stimulusName = o.stimulus;
    this.autostart = o.autostart;
    this.dwell = o.dwell;
    this.timeLimit = o.timeLimit;
    this.pause = o.pause;
    this.trial = new TacTrial(D, o.tolerance, o.euclidean);
    this.lastTarget = new Float64Array(D).fill(NaN);
    this.pos = new Float64Array(D);
    this.trialOut = ctx.output(vectorShape(5), "trial");
    this.targetOut = ctx.output(vectorShape(D), "target");
    if (ctx.declaredRate === undefined) ctx.setDesiredRate(0);
    this.describe(0);
  }

  instance(): BlockInstance {
    return {
      start: () => {
        this.started = true;
        this.listen();
        if (this.autostart) this.begin();
        this.describe(this.ctx.now());
      },
      stop: () => {
        this.started = false;
      },
      process: (f, port) => {
        if (f.n === 0) return;
        if (port === this.targetPort) this.processTargets(f);
        else this.processControl(f);
      },
      reset: () => this.reset(),
      dispose: () => {
        this.unlisten?.();
        this.unlisten = undefined;
        this.stim = undefined;
      },
      setParam: (name, value) => this.setParam(name, value),
      actions: this.actions(),
    };
  }

  private setParam(name: string, value: unknown): void {
    if (name === "Tolerance")
      this.trial.tol = this.perDof(value as number | number[], "Tolerance", "Tolerance");
    else if (name === "Dwell") this.dwell = value as number;
    else if (name === "TimeLimit") this.timeLimit = value as number;
    else if (name === "Pause") this.pause = value as number;
  }

  // -------------------------------------------------------------------------------------------
  // Control events

  /** Control events: each moves the position (a non-finite one: no position, the clock runs). */
  private processControl(f: Frame): void {
    const v = f.v;
    const D = this.D;
    let last = 0;
    for (let e = 0; e < f.n; e++) {
      const time = f.t[e]!;
      last = time;
      if (!this.readPosition(v, e * D)) {
        this.noPosition(time);
        continue;
      }
      this.havePos = true;
      if (this.running) this.step(time);
    }
    if (this.running && this.throttle.due(last)) this.describe(last);
  }

  /** Copies the position at `off` of `v` when all its values are finite; returns whether. */
  private readPosition(v: Float64Array, off: number): boolean {
    const D = this.D;
    for (let i = 0; i < D; i++) if (!Number.isFinite(v[off + i]!)) return false;
    for (let i = 0; i < D; i++) this.pos[i] = v[off + i]!;
    return true;
  }

  /** No position: neither inside nor moving, but the clock runs. */
  private noPosition(time: number): void {
    this.trial.inside = false;
    if (this.running && this.inTrial && time - this.trial.t0 >= this.timeLimit) {
      this.endTrial(time, false);
    }
  }

  /** One control event at `time` with the position in `pos`. */
  private step(time: number): void {
    if (!this.inTrial && !this.startDueTrial(time)) return;
    const trial = this.trial;
    if (trial.move(time, this.pos) && time - trial.entryT >= this.dwell) {
      this.endTrial(time, true);
      return;
    }
    if (time - trial.t0 >= this.timeLimit) this.endTrial(time, false);
  }

  /** Starts the trial due at `time` (the next of Targets, or a pending target); returns whether. */
  private startDueTrial(time: number): boolean {
    if (this.listMode) {
      if (this.k >= this.total || time < this.nextStart) return false;
      this.trial.goal.set(this.list[this.k]!);
      this.beginTrial(time, this.pos);
      return true;
    }
    if (!this.pending) return false;
    this.pending = false;
    this.beginTrial(Math.min(this.pendingT, time), this.pos);
    return true;
  }

  // -------------------------------------------------------------------------------------------
  // Trials

  private beginTrial(time: number, from: Float64Array): void {
    this.inTrial = true;
    this.trial.begin(time, from);
    this.showTarget(time, this.trial.goal);
    this.throttle.reset();
  }

  /** Ends the current trial at `time`, reports it and schedules the next one. */
  private endTrial(time: number, success: boolean): void {
    const completion = success ? time - this.trial.t0 : NaN;
    const efficiency = success ? this.trial.efficiency() : NaN;
    this.score.add(success, completion, efficiency);
    this.sendTrial(time, success, completion, efficiency);
    this.showTarget(time, null);
    this.inTrial = false;
    this.trial.inside = false;
    this.k++;
    this.nextStart = time + this.pause;
    this.throttle.reset();
    // MOSAIC's TAC moved its Stimulus on to fall when the target was reached.
    if (success) this.stim?.endCapture(time);
  }

  /** Output `trial`: index, success, completion time, path efficiency, final distance. */
  private sendTrial(time: number, success: boolean, completion: number, efficiency: number): void {
    const f = this.trialOut.frame(1);
    f.t[0] = time;
    f.v[0] = this.k;
    f.v[1] = success ? 1 : 0;
    f.v[2] = completion;
    f.v[3] = efficiency;
    f.v[4] = this.havePos ? this.trial.distanceTo(this.pos) : NaN;
    this.trialOut.emit(f);
  }

  /** Output `target`: the active target, or all NaN (`v` null) when a trial ends. */
  private showTarget(time: number, v: Float64Array | null): void {
    const f = this.targetOut.frame(1);
    f.t[0] = time;
    if (v) f.v.set(v);
    else f.v.fill(NaN, 0, this.D);
    this.targetOut.emit(f);
  }

  // -------------------------------------------------------------------------------------------
  // Targets (input mode)

  /** Target input events (trials come from the named Stimulus: the input only feeds displays). */
  private processTargets(f: Frame): void {
    if (!this.running || this.stim !== undefined) return;
    this.takeTargets(f);
  }

  private takeTargets(f: Frame): void {
    for (let e = 0; e < f.n; e++) this.onTarget(f.t[e]!, f.v, e * this.D);
    this.describe(f.t[f.n - 1]!);
  }

  /** A target event: a new target starts a trial, all NaN ends the current one. */
  private onTarget(time: number, v: Float64Array, off: number): void {
    const D = this.D;
    let nan = 0;
    for (let i = 0; i < D; i++) if (Number.isNaN(v[off + i]!)) nan++;
    if (nan > 0 && nan < D) {
      this.ctx.warn(
        `ignored a target event with ${nan} NaN of ${D} values: a target must be all numbers, ` +
          "and the end of a trial all NaN",
      );
      return;
    }
    if (nan === D) this.endOfTargets(time);
    else if (!this.isLastTarget(v, off)) this.newTarget(time, v, off);
  }

  /** All NaN: the current trial ends (a failure unless it already succeeded). */
  private endOfTargets(time: number): void {
    this.lastTarget.fill(NaN);
    this.pending = false;
    if (this.inTrial) this.endTrial(time, false);
  }

  private isLastTarget(v: Float64Array, off: number): boolean {
    let same = true;
    for (let i = 0; i < this.D; i++) if (this.lastTarget[i] !== v[off + i]) same = false;
    return same;
  }

  /** A different target: the current trial fails, the new one starts (at the next position). */
  private newTarget(time: number, v: Float64Array, off: number): void {
    for (let i = 0; i < this.D; i++) this.lastTarget[i] = v[off + i]!;
    if (this.inTrial) this.endTrial(time, false);
    this.trial.goal.set(this.lastTarget);
    if (this.havePos) this.beginTrial(time, this.pos);
    else {
      this.pending = true;
      this.pendingT = time;
    }
  }

  /** MOSAIC's form: the named Stimulus's capture phases are the trials. */
  private listen(): void {
    const name = this.stimulusName;
    if (name === undefined || this.unlisten) return;
    const s = lookup<StimulusTriggers>(this.ctx, name, "Stimulus");
    if (typeof s === "string") {
      this.ctx.warn(`Stimulus '${name}': ${s}; trials follow the target input instead`);
      return;
    }
    if (s.targetWidth !== this.D) {
      this.ctx.warn(
        `Stimulus '${name}' has targets of ${s.targetWidth} values, the control ${this.D}: ` +
          "trials follow the target input instead",
      );
      return;
    }
    this.stim = s;
    this.unlisten = s.onTrigger((f) => {
      if (this.running) this.takeTargets(f);
    });
  }

  // -------------------------------------------------------------------------------------------
  // Starting and stopping

  /** A new test: clears the results, from the first target. */
  private begin(): void {
    this.running = true;
    this.score.clear();
    this.k = 0;
    this.inTrial = false;
    this.pending = false;
    this.lastTarget.fill(NaN);
    this.nextStart = -Infinity;
    this.throttle.reset();
  }

  /** Ends the test now: a shown target is withdrawn, the trial in progress dropped. */
  private halt(): void {
    if (this.inTrial) this.showTarget(this.ctx.now(), null);
    this.inTrial = false;
    this.pending = false;
    this.running = false;
  }

  private reset(): void {
    this.halt();
    this.score.clear();
    this.k = 0;
    this.havePos = false;
    this.lastTarget.fill(NaN);
    if (this.started && this.autostart) this.begin();
    this.describe(this.ctx.now());
  }

  // -------------------------------------------------------------------------------------------
  // Status text and actions

  private describe(now: number): void {
    this.ctx.setText(this.statusText(now));
  }

  private statusText(now: number): string {
    const { score, total } = this;
    if (!this.running) {
      return score.trials > 0 ? `stopped: ${score.summary()}` : "ready (start to begin)";
    }
    if (total > 0 && this.k >= total) return `finished: ${score.summary()}`;
    if (this.inTrial) return this.trialText(now);
    if (total > 0) {
      const s = `${this.trialName()} in ${seconds(Math.max(0, this.nextStart - now))}`;
      return score.trials > 0 ? `${s} (${score.summary()})` : s;
    }
    return score.trials > 0 ? `waiting for a target (${score.summary()})` : "waiting for a target";
  }

  /** A trial in progress: the time inside, or the distance and the time left. */
  private trialText(now: number): string {
    const trial = this.trial;
    if (trial.inside) return `${this.trialName()}: inside ${(now - trial.entryT).toFixed(1)} s`;
    return (
      `${this.trialName()}: distance ${trial.lastDistance.toPrecision(3)}` +
      (Number.isFinite(this.timeLimit)
        ? `, ${seconds(Math.max(0, trial.t0 + this.timeLimit - now))} left`
        : "")
    );
  }

  /** "trial k/N" when the number of trials is known (the Targets list, the Stimulus's cues). */
  private trialName(): string {
    const n = this.total > 0 ? this.total : (this.stim?.cues ?? 0);
    return n > 0 ? `trial ${this.k + 1}/${n}` : `trial ${this.k + 1}`;
  }

  private actions(): Record<string, BlockAction> {
    return {
      start: {
        label: "Start",
        description: "Start a new test from the first target (clears the results)",
        run: () => {
          this.halt();
          this.begin();
          this.describe(this.ctx.now());
          return this.total > 0
            ? `started: ${plural(this.total, "trial")}`
            : "started: waiting for targets";
        },
      },
      stop: {
        label: "Stop",
        description: "Stop the test (the trial in progress is not counted)",
        run: () => {
          if (!this.running) return "not running";
          this.halt();
          this.describe(this.ctx.now());
          return `stopped: ${this.score.summary()}`;
        },
      },
      summary: {
        label: "Summary",
        description: "Success rate, mean completion time and mean path efficiency so far",
        run: () => this.score.summary(),
      },
    };
  }
}
