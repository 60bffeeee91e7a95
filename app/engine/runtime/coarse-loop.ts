/**
 * The fallback real-time loop for places without shared memory (a browser page that is not
 * cross-origin isolated cannot use Atomics.wait): it sleeps with the platform's timer until the
 * next wake-up and never polls. Browsers round nested timeouts up to ~4 ms, so it wakes later
 * than RealtimeLoop would; lossless timers then deliver the ticks that became due in one batch
 * (nothing is lost, the delivery delay shows the difference).
 */
import type { Clock } from "../clock";
import type { Runtime } from "./runtime";

export interface CoarseLoopOptions {
  runtime: Runtime;
  clock: Clock;
  /** The platform's `setTimeout` (milliseconds). */
  sleep: (fn: () => void, ms: number) => unknown;
  /** Runs `fn` on the next turn of the event loop (e.g. through a MessageChannel). */
  yieldNow: (fn: () => void) => void;
  telemetryIntervalS: number;
  /** `at`: when the step that reports began. */
  onTelemetry: (at: number) => void;
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
    if (delayS > 0) this.o.sleep(run, delayS * 1000);
    else this.o.yieldNow(run);
  }

  private turn(): void {
    if (this.stopped) return;
    const { runtime: rt, clock } = this.o;
    const at = clock.now();
    rt.step(at);
    const now = clock.now();
    if (now - this.lastTelemetry >= this.o.telemetryIntervalS) {
      this.lastTelemetry = now;
      this.o.onTelemetry(at);
    }
    if (rt.finished && !this.finishedReported) {
      this.finishedReported = true;
      this.o.onFinished();
    }
    const next = Math.min(rt.nextDeadline(), this.lastTelemetry + this.o.telemetryIntervalS);
    this.schedule(Math.max(0, next - clock.now()));
  }
}
