/**
 * One Stimulus's run (stimulus.ts): whether its protocol runs, the per-tick outputs (target,
 * phase, cue, progress) written from the protocol's schedule (stimulus-cycle.ts), the trigger
 * events of its capture phases (stimulus-triggers.ts), the status text and the actions.
 */
import {
  vectorShape,
  type BlockAction,
  type BlockContext,
  type BlockInstance,
  type Frame,
  type OutputPort,
} from "../../engine";
import { timerInput } from "../shared/inputs";
import { publish } from "../shared/named";
import { plural, TextThrottle } from "../shared/text";
import { seconds, targetColumnLabels } from "./labels";
import type { StimulusTriggers } from "./stimulus";
import { CAPTURE, END, PHASES, type CueCycle } from "./stimulus-cycle";
import { TriggerQueue } from "./stimulus-triggers";

/** The live duration params, in phase order (REST … FALL). */
const DURATION_PARAMS = ["Rest", "Rise", "Hold", "Capture", "Fall"] as const;

/** idle: not started; armed: starts at the next tick; running; ended; stopped (by the action). */
type RunState = "idle" | "armed" | "running" | "ended" | "stopped";

export interface StimulusProtocol {
  /** Label names and target vectors, by label index. */
  names: readonly string[];
  targets: readonly Float64Array[];
  cycle: CueCycle;
  /** Start the protocol when the pipeline starts. */
  autostart: boolean;
}

interface TickPorts {
  target: OutputPort;
  phase: OutputPort;
  cue: OutputPort;
  progress: OutputPort;
}

/** The frames of the per-tick outputs in one process call, filled tick by tick. */
class TickFrames {
  readonly target: Frame;
  readonly phase: Frame;
  readonly cue: Frame;
  readonly progress: Frame;
  n = 0;

  constructor(
    private readonly ports: TickPorts,
    room: number,
  ) {
    this.target = ports.target.frame(room);
    this.phase = ports.phase.frame(room);
    this.cue = ports.cue.frame(room);
    this.progress = ports.progress.frame(room);
  }

  /** Adds a tick at `t` to every frame; returns its index. */
  add(t: number): number {
    const k = this.n++;
    this.target.t[k] = t;
    this.phase.t[k] = t;
    this.cue.t[k] = t;
    this.progress.t[k] = t;
    return k;
  }

  emit(): void {
    const { ports, n } = this;
    this.target.n = n;
    this.phase.n = n;
    this.cue.n = n;
    this.progress.n = n;
    ports.target.emit(this.target);
    ports.phase.emit(this.phase);
    ports.cue.emit(this.cue);
    ports.progress.emit(this.progress);
  }
}

export class StimulusRun {
  private readonly names: readonly string[];
  private readonly targets: readonly Float64Array[];
  private readonly cycle: CueCycle;
  private readonly autostart: boolean;
  /** Values per target. */
  private readonly T: number;
  private readonly ports: TickPorts;
  private readonly triggers: TriggerQueue;
  /** `-Timer` (MOSAIC's form): subscribed only while the protocol runs. */
  private readonly onDemand: boolean;
  private readonly withdraw: () => void;
  private readonly throttle = new TextThrottle(0.1);
  private state: RunState = "idle";
  /** The pipeline runs. */
  private started = false;
  /** A capture phase's start was sent and its stop not yet. */
  private capturing = false;
  /** The last tick's time. */
  private lastT = 0;

  constructor(
    private readonly ctx: BlockContext,
    protocol: StimulusProtocol,
  ) {
    const timer = timerInput(ctx, 0);
    this.names = protocol.names;
    this.targets = protocol.targets;
    this.cycle = protocol.cycle;
    this.autostart = protocol.autostart;
    const T = this.targets[0]!.length;
    this.T = T;
    // One-hot targets name their columns (fist, open, …): panels and predictors show them.
    const columns = targetColumnLabels(this.names, this.targets);
    const target = ctx.output(vectorShape(T), "target", columns && { labels: columns });
    const phase = ctx.output(vectorShape(1), "phase");
    const trigger = ctx.output(vectorShape(T), "trigger", columns && { labels: columns });
    const cue = ctx.output(vectorShape(1), "cue");
    const progress = ctx.output(vectorShape(3), "progress", { labels: ["cue", "cues", "next"] });
    this.ports = { target, phase, cue, progress };
    this.triggers = new TriggerQueue(trigger, this.targets, T);
    this.onDemand = !timer.subscribed;
    // Blocks that read this Stimulus by name (a StimTrigger wired to its default output, as
    // MOSAIC's files write it) get every trigger frame as it is sent.
    this.withdraw = publish(ctx, "Stimulus", {
      targetWidth: T,
      cues: this.cycle.N,
      onTrigger: (fn: (f: Frame) => void) => this.triggers.listen(fn),
      endCapture: (t: number) => this.endCapture(t),
    } satisfies StimulusTriggers);
    this.describe(0);
  }

  instance(): BlockInstance {
    return {
      start: () => {
        this.started = true;
        if (this.autostart) this.begin();
        else this.subscribe(false);
      },
      stop: () => {
        this.started = false;
      },
      process: (f, port) => {
        if (port === 0) this.processTicks(f);
        // Skip input: any event ends the current capture phase at its time.
        else if (f.n > 0) this.endCapture(f.t[0]!);
      },
      dispose: () => {
        this.withdraw();
        this.triggers.dispose();
      },
      reset: () => {
        this.halt(this.started && this.autostart ? "armed" : "idle");
        this.lastT = 0;
        this.throttle.reset();
      },
      setParam: (name, value) => {
        const i = DURATION_PARAMS.indexOf(name as (typeof DURATION_PARAMS)[number]);
        if (i >= 0) this.cycle.setDuration(i, value as number, this.state === "running");
      },
      actions: this.actions(),
    };
  }

  private subscribe(on: boolean): void {
    if (this.onDemand) this.ctx.setSubscribed(0, on);
  }

  // -------------------------------------------------------------------------------------------
  // Ticks

  /** The timer's ticks: each moves the protocol to its time and writes one event per output. */
  private processTicks(f: Frame): void {
    let frames: TickFrames | null = null;
    for (let e = 0; e < f.n; e++) {
      if (this.state !== "armed" && this.state !== "running") break;
      const t = f.t[e]!;
      this.step(t);
      frames ??= new TickFrames(this.ports, f.n - e);
      this.writeTick(frames, t);
      if (this.cycle.phase === END) this.end();
      if (this.throttle.due(t)) this.describe(t);
    }
    this.triggers.flush();
    frames?.emit();
  }

  /** Moves the protocol to `t`: starts it when armed, leaves the phases that ended by then. */
  private step(t: number): void {
    this.lastT = t;
    if (this.state === "armed") this.startProtocol(t);
    const c = this.cycle;
    while (t >= c.phaseEnd) this.leavePhase(c.phaseEnd, t);
    if (c.phase === CAPTURE && !this.capturing) {
      this.capturing = true;
      this.triggers.push(t, c.label);
    }
  }

  private startProtocol(t: number): void {
    this.state = "running";
    this.cycle.begin(t);
    this.capturing = false;
    this.throttle.reset();
  }

  /** Leaves the current phase at time `at` (a capture's stop is stamped `stamp`). */
  private leavePhase(at: number, stamp: number): void {
    if (this.cycle.phase === CAPTURE && this.capturing) {
      this.capturing = false;
      this.triggers.push(stamp, -1);
    }
    this.cycle.advance(at);
    this.throttle.reset();
  }

  /** The tick at `t`: target (zeros at rest, the cue's target times the ramp's gain), phase, cue, progress. */
  private writeTick(frames: TickFrames, t: number): void {
    const k = frames.add(t);
    const c = this.cycle;
    const T = this.T;
    frames.phase.v[k] = c.phase;
    c.writeProgress(frames.progress.v, k * 3);
    const v = frames.target.v;
    const off = k * T;
    if (c.resting) {
      v.fill(0, off, off + T);
      frames.cue.v[k] = NaN;
      return;
    }
    const label = c.label;
    const tg = this.targets[label]!;
    const gain = c.gain(t);
    for (let i = 0; i < T; i++) v[off + i] = tg[i]! * gain;
    frames.cue.v[k] = label;
  }

  /** The END phase was sent: the protocol is over. */
  private end(): void {
    this.state = "ended";
    this.subscribe(false);
    this.throttle.reset();
  }

  /** Ends the current capture phase at `t` (the skip input, a TAC's success). */
  private endCapture(t: number): void {
    if (this.state !== "running" || this.cycle.phase !== CAPTURE) return;
    this.leavePhase(Math.max(t, this.cycle.phaseStart), t);
    this.triggers.flush();
    this.describe(t);
  }

  // -------------------------------------------------------------------------------------------
  // Starting and stopping

  /** Arms the protocol: it starts from the first cue at the next tick. */
  private begin(): void {
    this.state = "armed";
    this.cycle.rewind();
    this.subscribe(true);
    this.describe(this.lastT);
  }

  /** Ends the protocol now (stop action, reset): sends the stop of a capture in progress. */
  private halt(next: "idle" | "stopped" | "armed"): void {
    if (this.capturing) {
      this.capturing = false;
      this.triggers.push(this.ctx.now(), -1);
      this.triggers.flush();
    }
    this.state = next;
    this.subscribe(next === "armed");
    this.describe(this.ctx.now());
  }

  // -------------------------------------------------------------------------------------------
  // Status text and actions

  private describe(t: number): void {
    this.ctx.setText(this.statusText(t));
  }

  private statusText(t: number): string {
    const { cue, N, order, phase } = this.cycle;
    switch (this.state) {
      case "idle":
        return `ready: ${plural(N, "cue")} (start to begin)`;
      case "armed":
        return `starting: ${plural(N, "cue")}`;
      case "ended":
        return `done: ${plural(N, "cue")}`;
      case "stopped":
        return `stopped at ${this.names[order[Math.min(cue, N - 1)]!]} (${cue + 1} of ${N}), ${PHASES[phase]}`;
      case "running":
        if (phase === END) return `done: ${plural(N, "cue")}`;
        return (
          `${PHASES[phase]}: ${this.names[order[cue]!]} (${cue + 1} of ${N}), ` +
          `${seconds(Math.max(0, this.cycle.phaseEnd - t))} left`
        );
    }
  }

  /** Ends the current phase now. */
  private skip(): string {
    if (this.state !== "running") return "not running";
    const c = this.cycle;
    if (c.phase === END) return "the protocol is ending";
    const t = Math.max(this.ctx.now(), c.phaseStart);
    const from = PHASES[c.phase];
    this.leavePhase(t, t);
    this.triggers.flush();
    this.describe(t);
    return `skipped ${from}: now ${PHASES[c.phase]}`;
  }

  private actions(): Record<string, BlockAction> {
    return {
      start: {
        label: "Start",
        description:
          "Start the protocol from the first cue at the next tick (restarts it if running)",
        run: () => {
          if (this.state === "running" || this.state === "armed") this.halt("armed");
          else this.begin();
          return `starting: ${plural(this.cycle.N, "cue")}`;
        },
      },
      stop: {
        label: "Stop",
        description: "Stop the protocol (a capture in progress is stopped)",
        run: () => {
          if (this.state !== "running" && this.state !== "armed") return "not running";
          this.halt("stopped");
          return "stopped";
        },
      },
      skip: {
        label: "Skip",
        description: "End the current phase now (e.g. a capture the participant is not ready for)",
        run: () => this.skip(),
      },
    };
  }
}
