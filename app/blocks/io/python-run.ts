/**
 * One Python block at run time: sends its inputs to the sidecar without ever waiting for it in
 * real time, emits the results in order, counts what is late, skipped, failed or restarted, and
 * shows it in the status (the behaviour is described in the block's help, python.ts).
 */
import {
  BlockConfigError,
  formatShape,
  shapeSize,
  type BlockContext,
  type BlockInstance,
  type Frame,
  type OutputPort,
  type PythonBridge,
  type PythonCallError,
  type PythonLoadOptions,
  type PythonSidecar,
  type PythonSidecarState,
  type Shape,
} from "../../engine";
import { CallTimes, EventQueue, InFlightCalls, ms, running, type TakenCall } from "./python-queues";

const WARN_EVERY_MS = 5000;
/** Status percentiles are sorted again at most this often (counters are always current). */
const PERCENTILES_EVERY_MS = 100;

/** What the block's params and its input decide before the run starts. */
export interface PythonRunSettings {
  module: string;
  function: string;
  init?: string;
  params: Record<string, unknown>;
  onError: "hold" | "skip";
  maxInFlight: number;
  memoryLimitMb: number;
  inShape: Shape;
  declared: Shape | undefined;
  /** The budget of one call, ms (Infinity: none). */
  budgetMs: number;
  hardLimitMs: number;
  /** Which param a load error of this kind points at. */
  paramOf: (kind: string) => string;
}

export class PythonRun {
  private readonly budget: number | undefined;
  private readonly inSize: number;
  private readonly calls: InFlightCalls;
  /** Inputs waiting for a call: in real time one (newer ones replace it); virtual: all. */
  private readonly waiting: EventQueue;
  /** Results held for `flush` under the virtual clock (emitted in the engine's order). */
  private held: EventQueue | undefined;
  /** Last good output (OnError: hold). */
  private lastGood: Float64Array | undefined;
  private runningNow = false;
  private readonly counts = { calls: 0, errors: 0, overBudget: 0, skipped: 0, crashes: 0 };
  private state = "loading";
  /** The sidecar failed to restart: under the virtual clock, inputs are not waited for. */
  private down = false;
  private lastError = "";
  private lastWarnAt = -Infinity;
  private lastText = "";
  /** How long the oldest call has been running, when that is longer than the budget (ms). */
  private lateFor = 0;
  private readonly times = new CallTimes();
  private pctText = "";
  private lastPct = -Infinity;
  private sidecar: PythonSidecar | undefined;
  private out: OutputPort | undefined;

  constructor(
    private readonly ctx: BlockContext,
    private readonly s: PythonRunSettings,
  ) {
    this.budget = s.budgetMs < Infinity ? s.budgetMs : undefined;
    this.inSize = shapeSize(s.inShape);
    this.calls = new InFlightCalls(s.maxInFlight);
    this.waiting = new EventQueue(this.inSize, ctx.virtual ? 16 : 1);
  }

  /** Starts the sidecar and loads the function; a failure is the block's configuration error. */
  async load(bridge: PythonBridge, cwd: string): Promise<void> {
    let sidecar: PythonSidecar;
    try {
      sidecar = await bridge.load(this.loadOptions(cwd));
    } catch (e) {
      const kind = (e as { kind?: unknown }).kind;
      const message = e instanceof Error ? e.message : String(e);
      throw new BlockConfigError(
        `Python: ${message}`,
        this.s.paramOf(typeof kind === "string" ? kind : ""),
      );
    }
    this.sidecar = sidecar;
    this.state = "ready";
    this.out = this.ctx.output(sidecar.outputShape);
    const declared = this.s.declared;
    if (declared && shapeSize(declared) !== shapeSize(sidecar.outputShape)) {
      sidecar.close();
      throw new BlockConfigError(
        `Python: the function returns ${formatShape(sidecar.outputShape)}, not ${formatShape(declared)}`,
        "OutputShape",
      );
    }
    if (this.ctx.virtual) this.held = new EventQueue(shapeSize(sidecar.outputShape), 16);
    this.refresh(true);
  }

  private loadOptions(cwd: string): PythonLoadOptions {
    const s = this.s;
    return {
      module: s.module,
      function: s.function,
      ...(s.init !== undefined ? { init: s.init } : {}),
      params: s.params,
      inputShape: s.inShape,
      ...(s.declared ? { outputShape: s.declared } : {}),
      cwd,
      label: `block '${this.ctx.name}'`,
      hardLimitMs: s.hardLimitMs,
      ...(this.budget !== undefined ? { lateAfterMs: this.budget } : {}),
      memoryLimitMb: s.memoryLimitMb,
      onResult: (_id, values, computeUs) => this.onResult(values, computeUs),
      onLate: (_id, runningMs) => this.onLate(runningMs),
      onError: (id, e) => this.onError(id, e),
      onStatus: (status, message) => this.onStatus(status, message),
      onOutput: (line) => this.warnOutput(`python: ${line}`),
    };
  }

  /** The block's instance (after `load`). */
  instance(): BlockInstance {
    const sc = this.sidecar!;
    return {
      start: () => {
        this.runningNow = true;
        this.refresh(true);
      },
      stop: () => {
        this.runningNow = false;
        this.awaiting();
      },
      process: (frame: Frame) => this.process(frame),
      ...(this.held ? { flush: () => this.flush() } : {}),
      reset: () => {
        this.waiting.clear();
        this.held?.clear();
        this.lastGood = undefined;
        this.awaiting();
        sc.reset();
      },
      dispose: () => {
        this.runningNow = false;
        sc.close();
      },
      actions: {
        info: {
          label: "Sidecar info",
          description: "Shows the Python process, its versions and counters",
          run: () => this.info(),
        },
      },
    };
  }

  private info(): string {
    const sc = this.sidecar!;
    const c = this.counts;
    return (
      `${this.s.module}:${this.s.function} in pid ${sc.pid ?? "?"} (${sc.version}); ` +
      `${formatShape(this.s.inShape)} → ${formatShape(sc.outputShape)}; ${c.calls} calls, ` +
      `${c.overBudget} over budget, ${c.errors} errors, ${c.skipped} skipped, ${c.crashes} restarts`
    );
  }

  private process(frame: Frame): void {
    const stride = frame.stride;
    for (let e = 0; e < frame.n; e++) {
      const v = frame.v.subarray(e * stride, e * stride + this.inSize);
      this.input(v, frame.t[e]!);
    }
    this.awaiting();
    this.refresh();
  }

  /** One input: a call now, or it waits (real time: replacing an older waiting one). */
  private input(v: Float64Array, t: number): void {
    const waiting = this.waiting;
    if (waiting.n === 0 && this.send(v, t)) return;
    if (this.ctx.virtual) {
      // Every input gets its call (unless the sidecar cannot be restarted).
      if (this.down) this.counts.skipped++;
      else waiting.push(v, t);
    } else if (waiting.n > 0) {
      // Busy (or restarting): this input waits, replacing an older waiting one.
      this.counts.skipped++;
      waiting.replaceNewest(v, t);
    } else {
      waiting.push(v, t);
    }
  }

  /**
   * Under the virtual clock results are held until the engine has delivered everything it had
   * (it waits for them), then go out here, in the engine's order of blocks.
   */
  private flush(): void {
    const h = this.held!;
    if (h.n === 0 || !this.runningNow) {
      h.clear();
      return;
    }
    const f = this.out!.frame(h.n);
    for (let i = 0; i < f.n; i++) {
      f.t[i] = h.oldestT;
      f.v.set(h.oldest, i * f.stride);
      h.shift();
    }
    this.out!.emit(f);
  }

  private send(values: Float64Array, t: number): boolean {
    const sc = this.sidecar;
    if (this.calls.full || !sc?.ready) return false;
    this.calls.add(t);
    if (sc.call(values) < 0) {
      this.calls.dropNewest();
      return false;
    }
    return true;
  }

  private sendWaiting(): void {
    const w = this.waiting;
    while (w.n > 0 && this.send(w.oldest, w.oldestT)) w.shift();
  }

  /** Under the virtual clock: how many results the engine must wait for. */
  private awaiting(): void {
    if (this.ctx.virtual)
      this.ctx.setAwaiting(this.runningNow ? this.calls.count + this.waiting.n : 0);
  }

  private emit(t: number, values: Float64Array): void {
    if (!this.runningNow) return;
    if (this.held) {
      this.held.push(values, t);
      return;
    }
    const f = this.out!.frame(1);
    f.t[0] = t;
    f.v.set(values);
    this.out!.emit(f);
  }

  private warnOutput(message: string): void {
    const now = performance.now();
    if (now - this.lastWarnAt < WARN_EVERY_MS) return;
    this.lastWarnAt = now;
    this.ctx.warn(message);
  }

  /**
   * An error: counted by the runtime like an exception in `process`; the status counts the
   * function's errors (a lost process shows as a restart).
   */
  private failed(message: string, traceback = "", restart = false): void {
    if (!restart) {
      this.counts.errors++;
      this.lastError = message;
    }
    this.ctx.error(message, traceback.trimEnd() || undefined);
  }

  /** The oldest call, still running past the budget: counted now, and marks it stumbling. */
  private onLate(runningMs: number): void {
    if (this.calls.count === 0 || this.budget === undefined) return;
    if (this.calls.markOldestLate()) this.counts.overBudget++;
    this.lateFor = runningMs;
    this.ctx.reportCompute(runningMs, this.budget);
    this.refresh(true);
  }

  /** The oldest call is done (answered or lost): counted, its time is this block's compute. */
  private finishCall(): TakenCall | undefined {
    const taken = this.calls.take();
    if (!taken) return undefined;
    this.lateFor = 0;
    if (taken.tookMs > this.s.budgetMs && !taken.countedLate) this.counts.overBudget++;
    // The call's duration is this block's compute: a call over budget marks it stumbling.
    this.ctx.reportCompute(taken.tookMs, this.budget);
    return taken;
  }

  private onResult(values: Float64Array, computeUs: number): void {
    const taken = this.finishCall();
    if (!taken) return;
    this.counts.calls++;
    this.times.add(taken.tookMs, computeUs / 1000);
    if (!this.lastGood) this.lastGood = new Float64Array(values.length);
    this.lastGood.set(values);
    this.emit(taken.t, values);
    this.sendWaiting();
    this.awaiting();
    this.refresh();
  }

  private onError(id: number, e: PythonCallError): void {
    if (id === 0) {
      // Not a call: init raised on reset.
      this.failed(e.message, e.traceback);
      this.refresh(true);
      return;
    }
    // A call lost to a crash or a kill: the restart's report counts it (once per process).
    if (e.kind !== "crash" && e.kind !== "timeout") this.failed(e.message, e.traceback);
    const taken = this.finishCall();
    if (taken && this.s.onError === "hold" && this.lastGood) this.emit(taken.t, this.lastGood);
    this.sendWaiting();
    this.awaiting();
    this.refresh(true);
  }

  private onStatus(status: PythonSidecarState, message?: string): void {
    if (!this.sidecar) return; // the load itself: its outcome is what `load` returns
    if (status === "restarting")
      this.restarting(message ?? "the Python sidecar stopped; restarting");
    else if (status === "ready") {
      this.state = "ready";
      this.down = false;
      if (message) this.ctx.warn(`Python sidecar ${message}`);
      this.sendWaiting();
    } else if (status === "closed") {
      this.state = "closed";
    }
    this.awaiting();
    this.refresh(true);
  }

  private restarting(text: string): void {
    if (this.state === "ready") {
      // The process died (or was killed): one error, whatever it had in flight.
      this.counts.crashes++;
      this.failed(text, "", true);
    } else {
      // A restart failed: the same outage goes on.
      this.ctx.warn(text);
      this.down = true;
      if (this.ctx.virtual && this.waiting.n > 0) {
        this.counts.skipped += this.waiting.n;
        this.waiting.clear();
      }
    }
    this.state = text;
    this.calls.clear();
    this.lateFor = 0;
  }

  private refresh(force = false): void {
    const now = performance.now();
    // Percentiles at most every 100 ms (a sort of the last 256 call times); counters always.
    if (force || now - this.lastPct >= PERCENTILES_EVERY_MS || this.times.n < 8) {
      this.lastPct = now;
      this.pctText = this.times.summary();
    }
    const text = this.statusText();
    if (text !== this.lastText) {
      this.lastText = text;
      this.ctx.setText(text);
    }
  }

  private statusText(): string {
    const c = this.counts;
    let text: string;
    if (this.state === "ready") {
      text = `pid ${this.sidecar?.pid ?? "?"}`;
      if (this.lateFor > 0) text += ` · call running for ${running(this.lateFor)}`;
      text += ` · ${this.pctText}`;
      text += ` · ${c.overBudget} over budget${this.budget !== undefined ? ` (${ms(this.budget)})` : ""}`;
    } else {
      text = this.state;
    }
    if (c.skipped > 0) text += ` · ${c.skipped} skipped`;
    if (c.crashes > 0) text += ` · ${c.crashes} restart${c.crashes > 1 ? "s" : ""}`;
    if (c.errors > 0) text += ` · ${c.errors} errors (last: ${this.lastError})`;
    return text;
  }
}
