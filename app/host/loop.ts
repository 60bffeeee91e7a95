/**
 * The real-time loop of an engine worker (DESIGN.md §3 Scheduling).
 *
 * Far from the next deadline the worker sleeps in its event loop (`Atomics.waitAsync` on its
 * doorbell, so I/O callbacks, control messages and frames from other workers wake it at once).
 * Within COARSE of the deadline it yields to the event loop once (I/O still runs every tick), then
 * blocks in `Atomics.wait` until slightly before the deadline — "slightly" is learned from the
 * observed wake-up overshoot so that ticks land on time without spinning. Precision mode spins the
 * last ~0.3 ms instead. Missed deadlines are skipped and counted by the scheduler, never burst.
 */
import type { Clock } from "../engine/clock";
import type { Runtime } from "../engine/runtime/runtime";

const COARSE_S = 0.002;
const PRECISION_SPIN_S = 0.0003;
const MAX_MARGIN_S = 0.0002;

export interface LoopOptions {
  runtime: Runtime;
  clock: Clock;
  /** Int32Array over a SharedArrayBuffer: bumped + notified to wake this worker. */
  doorbell: Int32Array;
  precision: boolean;
  telemetryIntervalS: number;
  onTelemetry: () => void;
  onFinished: () => void;
}

export class RealtimeLoop {
  private stopped = true;
  private lastTelemetry = -Infinity;
  /** EWMA of how late Atomics.wait returns after its timeout (s). */
  private overshoot = 0.00006;
  private finishedReported = false;

  constructor(private readonly o: LoopOptions) {}

  get margin(): number {
    // Aim a little after the deadline rather than before it: ticks should not fire early.
    return Math.min(MAX_MARGIN_S, Math.max(0, this.overshoot - 0.000015));
  }

  start(): void {
    if (!this.stopped) return;
    this.stopped = false;
    this.lastTelemetry = this.o.clock.now();
    setImmediate(this.tick);
  }

  stop(): void {
    this.stopped = true;
    this.wake();
  }

  /** Re-plans the wait now (a timer started, a control message arrived, ...). */
  wake(): void {
    Atomics.add(this.o.doorbell, 0, 1);
    Atomics.notify(this.o.doorbell, 0);
  }

  private readonly tick = (): void => {
    if (this.stopped) return;
    const { runtime: rt, clock } = this.o;
    rt.scheduler.earlyTolerance = this.o.precision ? 0.000002 : this.margin + 0.000002;
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
    this.plan();
  };

  private nextDeadline(): number {
    return Math.min(this.o.runtime.nextDeadline(), this.lastTelemetry + this.o.telemetryIntervalS);
  }

  private plan(): void {
    if (this.stopped) return;
    const bell = this.o.doorbell;
    const seen = Atomics.load(bell, 0);
    const remaining = this.nextDeadline() - this.o.clock.now();
    if (remaining > COARSE_S) {
      const r = Atomics.waitAsync(bell, 0, seen, (remaining - COARSE_S) * 1000);
      if (r.async) r.value.then(this.tick, this.tick);
      else setImmediate(this.tick);
    } else {
      setImmediate(this.fine);
    }
  }

  private readonly fine = (): void => {
    if (this.stopped) return;
    const { clock, doorbell } = this.o;
    const deadline = this.nextDeadline();
    const seen = Atomics.load(doorbell, 0);
    if (this.o.precision) {
      const sleep = deadline - PRECISION_SPIN_S - clock.now();
      if (sleep > 0) Atomics.wait(doorbell, 0, seen, sleep * 1000);
      while (clock.now() < deadline && Atomics.load(doorbell, 0) === seen) {
        // spin: precision mode trades a little CPU for sub-10 µs ticks
      }
    } else {
      const target = deadline - this.margin;
      const sleep = target - clock.now();
      if (sleep > 0) {
        const res = Atomics.wait(doorbell, 0, seen, sleep * 1000);
        if (res === "timed-out") {
          const over = clock.now() - target;
          if (over >= 0 && over < 0.002) this.overshoot += 0.05 * (over - this.overshoot);
        }
      }
    }
    this.tick();
  };
}
