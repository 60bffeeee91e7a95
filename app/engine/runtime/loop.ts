/**
 * The real-time loop of an engine worker (DESIGN.md §3 Scheduling), for Node worker_threads and
 * for browser Web Workers with shared memory (cross-origin isolated pages).
 *
 * The worker wakes when the scheduler asks (`Runtime.nextDeadline`: with batching, the deadline of
 * the last tick that may wait for the others, so one wake-up fires several ticks of every timer)
 * and runs everything due. Between wake-ups it blocks in `Atomics.wait` on its doorbell and wakes
 * slightly before the target — "slightly" is learned from the observed wake-up overshoot, so
 * ticks land on time without spinning; precision mode spins the last ~0.3 ms instead. Frames from
 * other workers and control messages ring the doorbell, so they wake the worker at once.
 *
 * Wake-ups are the main cost of a timer (on the 2-core VM of the benches a bare 2 kHz sleep loop
 * costs ~2–5 % of a core, whatever the language), so the loop avoids extra ones:
 * - a worker without I/O blocks yields to its event loop only when a control message is waiting,
 *   or every YIELD_S, not after every wake-up;
 * - a worker with I/O blocks (`eventLoop: true`, e.g. a UDP receiver) sleeps in its event loop
 *   (`Atomics.waitAsync`, whose timeout is precise to ~0.1 ms in Node) until just before the
 *   target, so a datagram wakes it at once; the learned overshoot of that wait is the only part
 *   spent blocked in `Atomics.wait`. It never polls.
 */
import type { Clock } from "../clock";
import type { Runtime } from "./runtime";

const PRECISION_SPIN_S = 0.0003;
/** Longest blocking wait left after an event-loop sleep (beyond it, sleep in the event loop again). */
const MAX_ASYNC_MARGIN_S = 0.001;
const MAX_MARGIN_S = 0.0002;
/** Longest blocking wait, and longest time between event-loop turns, for workers without I/O. */
const MAX_BLOCK_S = 0.02;
const YIELD_S = 0.05;

/** Doorbell slots: [0] bumped by anyone who wants the worker to look (data, control); [1] control messages waiting. */
export const BELL_WAKE = 0;
export const BELL_CONTROL = 1;

export interface LoopOptions {
  runtime: Runtime;
  /** Runs `fn` on the next turn of the event loop (Node: setImmediate; browsers: a MessageChannel). */
  yieldNow: (fn: () => void) => void;
  clock: Clock;
  /** Int32Array(2) over a SharedArrayBuffer (see BELL_WAKE, BELL_CONTROL). */
  doorbell: Int32Array;
  precision: boolean;
  telemetryIntervalS: number;
  /** `at`: when the step that reports began. */
  onTelemetry: (at: number) => void;
  onFinished: () => void;
}

export class RealtimeLoop {
  private stopped = true;
  private lastTelemetry = -Infinity;
  private lastYield = -Infinity;
  /** EWMA of how late Atomics.wait returns after its timeout (s). */
  private overshoot = 0.00006;
  /** EWMA of how late Atomics.waitAsync resolves after its timeout (s). */
  private asyncOvershoot = 0.00015;
  private finishedReported = false;
  private readonly eventLoop: boolean;

  constructor(private readonly o: LoopOptions) {
    this.eventLoop = o.runtime.needsEventLoop;
  }

  get margin(): number {
    // Aim a little after the deadline rather than before it: ticks should not fire early.
    return Math.min(MAX_MARGIN_S, Math.max(0, this.overshoot - 0.000015));
  }

  start(): void {
    if (!this.stopped) return;
    this.stopped = false;
    this.lastTelemetry = this.o.clock.now();
    this.o.yieldNow(this.turn);
  }

  stop(): void {
    this.stopped = true;
    this.wake();
  }

  /** Makes the loop look again now (a timer started, frames arrived, ...). */
  wake(): void {
    Atomics.add(this.o.doorbell, BELL_WAKE, 1);
    Atomics.notify(this.o.doorbell, BELL_WAKE);
    // On a worker with I/O, a wake-up comes from an I/O callback (a datagram became a frame):
    // deliver right after the callback returns, not a turn of the event loop later.
    if (this.eventLoop && !this.stepSoon && !this.stopped) {
      this.stepSoon = true;
      queueMicrotask(this.stepNow);
    }
  }

  private stepSoon = false;
  private readonly stepNow = (): void => {
    this.stepSoon = false;
    if (!this.stopped) this.step();
  };

  /**
   * The next wake-up: the scheduler's, or the telemetry's when no tick comes soon enough. Telemetry
   * rides on the wake-ups that ticks cause anyway (a wake-up of its own costs as much as a tick's);
   * only a worker with no tick within half an interval after it is due wakes for it.
   */
  private nextDeadline(): number {
    const interval = this.o.telemetryIntervalS;
    return Math.min(this.o.runtime.nextDeadline(), this.lastTelemetry + 1.5 * interval);
  }

  /** Fires what is due, delivers, reports. */
  private step(): void {
    const { runtime: rt, clock } = this.o;
    rt.scheduler.earlyTolerance = this.o.precision ? 0.000002 : this.margin + 0.000002;
    const at = clock.now();
    rt.step(at);
    const now = clock.now();
    const interval = this.o.telemetryIntervalS;
    if (now - this.lastTelemetry >= interval) {
      // Keep the average cadence (a report rides on the first wake-up after it is due).
      this.lastTelemetry =
        now - this.lastTelemetry < 2 * interval ? this.lastTelemetry + interval : now;
      this.o.onTelemetry(at);
    }
    if (rt.finished && !this.finishedReported) {
      this.finishedReported = true;
      this.o.onFinished();
    }
  }

  /** One turn of the event loop: step, then wait (blocking) until the loop must yield again. */
  private readonly turn = (): void => {
    if (this.stopped) return;
    if (this.eventLoop && typeof Atomics.waitAsync === "function") {
      this.ioTurn();
      return;
    }
    const { clock, doorbell } = this.o;
    this.lastYield = clock.now();
    Atomics.store(doorbell, BELL_CONTROL, 0);
    for (;;) {
      this.step();
      if (this.stopped) return;
      const now = clock.now();
      const remaining = this.nextDeadline() - now;
      if (Atomics.load(doorbell, BELL_CONTROL) !== 0 || now - this.lastYield >= YIELD_S) {
        this.o.yieldNow(this.turn);
        if (remaining > 0.0005) return;
        // A deadline is imminent: wait for it first, the event loop turns right after.
        this.sleepUntilDeadline(MAX_BLOCK_S);
        return;
      }
      this.sleepUntilDeadline(MAX_BLOCK_S);
    }
  };

  /**
   * A turn of a worker with I/O blocks: step, then sleep in the event loop (so that I/O callbacks
   * run as soon as data arrives) until the learned overshoot before the next target, and block
   * only for that last bit.
   */
  private ioTurn(): void {
    const { clock, doorbell } = this.o;
    Atomics.store(doorbell, BELL_CONTROL, 0);
    this.step();
    if (this.stopped) return;
    const target = this.nextDeadline();
    const asyncMargin = Math.min(MAX_ASYNC_MARGIN_S, this.asyncOvershoot + 0.00005);
    const remaining = target - clock.now();
    if (remaining <= asyncMargin) {
      if (remaining > 0) this.sleepUntilDeadline(MAX_ASYNC_MARGIN_S);
      this.o.yieldNow(this.turn);
      return;
    }
    const seen = Atomics.load(doorbell, BELL_WAKE);
    const sleepS = Math.min(remaining - asyncMargin, YIELD_S);
    const r = Atomics.waitAsync(doorbell, BELL_WAKE, seen, sleepS * 1000);
    if (!r.async) {
      this.o.yieldNow(this.turn);
      return;
    }
    const wantAt = clock.now() + sleepS;
    void r.value.then((how) => {
      if (how === "timed-out" && sleepS < YIELD_S) {
        const over = clock.now() - wantAt;
        if (over >= 0 && over < 0.005) this.asyncOvershoot += 0.05 * (over - this.asyncOvershoot);
      }
      this.turn();
    }, this.turn);
  }

  /** Blocks until just before the next deadline (at most `maxS`) or until the doorbell rings. */
  private sleepUntilDeadline(maxS: number): void {
    const { clock, doorbell } = this.o;
    const deadline = this.nextDeadline();
    const seen = Atomics.load(doorbell, BELL_WAKE);
    if (this.o.precision) {
      const sleep = Math.min(maxS, deadline - PRECISION_SPIN_S - clock.now());
      if (sleep > 0) Atomics.wait(doorbell, BELL_WAKE, seen, sleep * 1000);
      if (deadline - clock.now() <= PRECISION_SPIN_S) {
        while (clock.now() < deadline && Atomics.load(doorbell, BELL_WAKE) === seen) {
          // spin: precision mode trades a little CPU for sub-10 µs ticks
        }
      }
      return;
    }
    const target = deadline - this.margin;
    const sleep = Math.min(maxS, target - clock.now());
    if (sleep <= 0) return;
    const res = Atomics.wait(doorbell, BELL_WAKE, seen, sleep * 1000);
    if (res === "timed-out" && sleep < maxS) {
      const over = clock.now() - target;
      if (over >= 0 && over < 0.002) this.overshoot += 0.05 * (over - this.overshoot);
    }
  }
}
