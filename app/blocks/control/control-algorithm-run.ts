/**
 * One ControlAlgorithm's run (control-algorithm.ts): each prediction turned into the next output
 * by the strategy (control-dofs.ts), slew-limited and clipped; the watchdog that sends the safe
 * output when predictions stop; the status text and the live params.
 */
import {
  vectorShape,
  type BlockContext,
  type BlockInstance,
  type Frame,
  type OutputPort,
} from "../../engine";
import { DofDrive, type DofTable, type Strategy } from "./control-dofs";

export interface ControlOptions {
  strategy: "direct" | "stepwise";
  gain: number;
  deadZone: number;
  slewRate: number;
  /** Watchdog: seconds without a prediction (0: off), and what it sends. */
  timeout: number;
  safe: "rest" | "hold" | number[];
}

export class ControlRun {
  private readonly m: number;
  private readonly drive: DofDrive;
  private strategyName: "direct" | "stepwise";
  private strategy: Strategy;
  private gainDefault: number;
  private deadDefault: number;
  private slew: number;
  private readonly timeout: number;
  private readonly safe: "rest" | "hold" | number[];
  /** The values sent last, and the strategy's targets before slew limiting and clipping. */
  private readonly current: Float64Array;
  private readonly target: Float64Array;
  private lastT = NaN;
  private watchdogTripped = false;
  private running = false;
  /** Δt of the first prediction (or one not later than the previous). */
  private readonly nominalDt: number;
  /** Rate of the safe output once the watchdog tripped. */
  private readonly safeHz: number;
  private readonly out: OutputPort;
  private readonly onTimeout = (t: number): void => this.trip(t);

  constructor(
    private readonly ctx: BlockContext,
    private readonly dofs: DofTable,
    o: ControlOptions,
  ) {
    const m = dofs.m;
    this.m = m;
    this.drive = new DofDrive(dofs);
    this.gainDefault = o.gain;
    this.deadDefault = o.deadZone;
    this.slew = o.slewRate;
    this.strategyName = o.strategy;
    this.timeout = o.timeout;
    this.safe = o.safe;
    this.drive.apply(this.gainDefault, this.deadDefault);
    this.strategy = this.strategyName === "direct" ? this.drive.direct : this.drive.stepwise;
    this.current = Float64Array.from(dofs.rest, (r, i) =>
      Math.min(dofs.hi[i]!, Math.max(dofs.lo[i]!, r)),
    );
    this.target = new Float64Array(m);
    this.nominalDt = ctx.desiredRate > 0 ? 1 / ctx.desiredRate : 0.04;
    this.out = ctx.output(vectorShape(m));
    this.describe();
    this.safeHz = ctx.desiredRate > 0 ? ctx.desiredRate : 10;
  }

  instance(): BlockInstance {
    return {
      start: () => {
        this.running = true;
      },
      stop: () => {
        this.running = false;
      },
      process: (f) => this.process(f),
      reset: () => this.reset(),
      setParam: (name, value) => this.setParam(name, value),
    };
  }

  /** Each prediction: the strategy's targets, settled into the output; re-arms the watchdog. */
  private process(f: Frame): void {
    const { m, current, target } = this;
    const o = this.out.frame(f.n);
    const s = f.stride;
    for (let e = 0; e < f.n; e++) {
      const t = f.t[e]!;
      const dt = this.lastT === this.lastT && t > this.lastT ? t - this.lastT : this.nominalDt;
      this.lastT = t;
      this.strategy.step(f.v, e * s, dt, current, target);
      this.settle(dt);
      o.t[e] = t;
      for (let i = 0; i < m; i++) o.v[e * m + i] = current[i]!;
    }
    if (this.watchdogTripped) {
      this.watchdogTripped = false;
      this.describe();
    }
    this.out.emit(o);
    if (this.timeout > 0 && this.running)
      this.ctx.at(this.ctx.now() + this.timeout, this.onTimeout);
  }

  /** Slew limit and clip `target` into `current` over dt seconds. */
  private settle(dt: number): void {
    const { m, current, target } = this;
    const { lo, hi } = this.dofs;
    const maxStep = this.slew === Infinity ? Infinity : this.slew * dt;
    for (let i = 0; i < m; i++) {
      let v = target[i]!;
      if (v !== v) v = current[i]!; // a NaN prediction leaves the value where it is
      const d = v - current[i]!;
      if (d > maxStep) v = current[i]! + maxStep;
      else if (d < -maxStep) v = current[i]! - maxStep;
      current[i] = v < lo[i]! ? lo[i]! : v > hi[i]! ? hi[i]! : v;
    }
  }

  /**
   * Watchdog: a one-shot re-armed by every prediction, so it costs nothing while predictions
   * flow; once tripped it keeps sending the safe output at the desired rate (or 10 Hz).
   */
  private trip(t: number): void {
    if (!this.watchdogTripped) {
      this.watchdogTripped = true;
      this.ctx.warn(`no prediction for ${this.timeout} s: sending the safe output`);
      this.describe();
    }
    this.setSafeTarget();
    this.settle(1 / this.safeHz);
    const f = this.out.frame(1);
    f.t[0] = t;
    for (let i = 0; i < this.m; i++) f.v[i] = this.current[i]!;
    this.out.emit(f);
    this.ctx.at(t + 1 / this.safeHz, this.onTimeout);
  }

  /** Safe: each DoF's Rest, its last value (hold), or the values given. */
  private setSafeTarget(): void {
    const { m, target, current, safe } = this;
    const rest = this.dofs.rest;
    for (let i = 0; i < m; i++) {
      target[i] = safe === "rest" ? rest[i]! : safe === "hold" ? current[i]! : safe[i]!;
    }
  }

  private reset(): void {
    const { rest, lo, hi } = this.dofs;
    for (let i = 0; i < this.m; i++) {
      this.current[i] = Math.min(hi[i]!, Math.max(lo[i]!, rest[i]!));
    }
    this.lastT = NaN;
    this.watchdogTripped = false;
    this.describe();
  }

  private setParam(name: string, value: unknown): void {
    if (name === "Gain") this.gainDefault = value as number;
    else if (name === "DeadZone") this.deadDefault = value as number;
    else if (name === "SlewRate") this.slew = value as number;
    else if (name === "Strategy") {
      this.strategyName = value as "direct" | "stepwise";
      this.strategy = this.strategyName === "direct" ? this.drive.direct : this.drive.stepwise;
      this.describe();
    }
    this.drive.apply(this.gainDefault, this.deadDefault);
  }

  private describe(): void {
    const m = this.m;
    this.ctx.setText(
      this.watchdogTripped
        ? `watchdog: no prediction for ${this.timeout} s, sending ${Array.isArray(this.safe) ? "the safe values" : this.safe}`
        : `${this.strategyName}, ${m} DoF${m === 1 ? "" : "s"}`,
    );
  }
}
