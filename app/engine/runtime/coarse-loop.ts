/**
 * The fallback real-time loop for places without shared memory (a browser page that is not
 * cross-origin isolated cannot use Atomics.wait): it sleeps with the platform's timer until the
 * next deadline, and polls through the event loop for waits shorter than the timer's clamping
 * (browsers round nested timeouts up to ~4 ms). Ticks are less precise than with RealtimeLoop;
 * late ones are skipped and counted by the scheduler, and the status shows it.
 */
import type { Clock } from "../clock";
import type { Runtime } from "./runtime";

/** Below this, `setTimeout` is too coarse: poll through the event loop instead. */
const TIMER_GRAIN_S = 0.004;

export interface CoarseLoopOptions {
  runtime: Runtime;
  clock: Clock;
  /** The platform's `setTimeout` (milliseconds). */
  sleep: (fn: () => void, ms: number) => unknown;
  /** Runs `fn` on the next turn of the event loop (e.g. through a MessageChannel). */
  yieldNow: (fn: () => void) => void;
  telemetryIntervalS: number;
  onTelemetry: () => void;
  onFinished: () => void;
}

export class CoarseLoop {
  private stopped = true;
  private lastTelemetry = -Infinity;
  private finishedReported = false;
  private generation = 0;

  constructor(private readonly o: CoarseLoopOptions) {}

  start(): void {
    if (!this.stopped) return;
    this.stopped = false;
    this.lastTelemetry = this.o.clock.now();
    this.schedule(0);
  }

  stop(): void {
    this.stopped = true;
    this.generation++;
  }

  wake(): void {
    if (this.stopped) return;
    this.generation++;
    this.schedule(0);
  }

  private schedule(delayS: number): void {
    const gen = this.generation;
    const run = (): void => {
      if (gen === this.generation) this.turn();
    };
    if (delayS >= TIMER_GRAIN_S) this.o.sleep(run, (delayS - TIMER_GRAIN_S / 2) * 1000);
    else this.o.yieldNow(run);
  }

  private turn(): void {
    if (this.stopped) return;
    const { runtime: rt, clock } = this.o;
    rt.step(clock.now());
    const now = clock.now();
    if (now - this.lastTelemetry >= this.o.telemetryIntervalS) {
      this.lastTelemetry = now;
      this.o.onTelemetry();
    }
    if (rt.finished && !this.finishedReported) {
      this.finishedReported = true;
      this.o.onFinished();
    }
    const next = Math.min(rt.nextDeadline(), this.lastTelemetry + this.o.telemetryIntervalS);
    this.schedule(Math.max(0, next - clock.now()));
  }
}
