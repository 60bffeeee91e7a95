/**
 * One BrainFlow block's run (app/blocks/devices/brainflow.ts): the sidecar loaded by
 * brainflow-link.ts, the poll timer, the frames emitted from each poll's result, and the status
 * line with the board's state and counts.
 */
import {
  vectorShape,
  type BlockContext,
  type BlockInstance,
  type OutputPort,
  type PythonCallError,
  type PythonSidecar,
  type TimerHandle,
} from "../../engine";
import { plural, TextThrottle } from "../shared/text";
import {
  BoardState,
  CMD_POLL,
  CMD_STOP,
  H_N,
  loadBoard,
  readCounts,
  stateText,
  type BoardCounts,
  type BoardLink,
} from "./brainflow-link";
import { DeviceClock } from "./delsys-protocol";

const WARN_EVERY_S = 5;

const VIRTUAL_WARNING =
  "BrainFlow boards run in real time: under the virtual clock this block emits what the board " +
  "delivered by each poll, so a fast virtual run gets few samples; run it in real time";

const AXES = ["x", "y", "z"];
const AXIS_KINDS = new Set(["accel", "gyro", "magnetometer"]);

/** "exg 1", "exg 2", …, "accel x" … per output channel. */
export function channelNames(kinds: readonly string[], counts: readonly number[]): string[] {
  const names: string[] = [];
  kinds.forEach((kind, k) => {
    const n = counts[k] ?? 0;
    const axes = n === 3 && AXIS_KINDS.has(kind) ? AXES : undefined;
    for (let i = 0; i < n; i++) names.push(`${kind} ${axes ? axes[i]! : i + 1}`);
  });
  return names;
}

export interface RunOptions {
  /** "board CYTON_BOARD (/dev/ttyUSB0)", for messages. */
  target: string;
  /** A playback board: its file's end finishes the run. */
  playback: boolean;
  pollRate: number;
  /** The `Channels` kinds, in order. */
  kinds: readonly string[];
}

/** The sidecar's module failures are RuntimeErrors whose message is the sentence to show. */
const failureText = (message: string): string =>
  message.replace(/^RuntimeError: /, "").replace(/ \(at [^()]*, in poll\)$/, "");

export class BrainFlowRun {
  private readonly counts: BoardCounts = {
    state: 0,
    lost: 0,
    reconnects: 0,
    failures: 0,
    total: 0,
  };
  private readonly throttle = new TextThrottle(0.5);
  private emitted = 0;
  private restarts = 0;
  private lastFailure = "";
  private sidecarDown = "";
  private lastText = "";
  private lastLost = 0;
  private lastReconnects = 0;
  private lastWarn = -Infinity;
  private inFlight = false;
  private running = false;
  private finished = false;
  private link: BoardLink | undefined;
  private out: OutputPort | undefined;
  private clock: DeviceClock | undefined;
  private timer: TimerHandle | undefined;
  private names: string[] = [];

  constructor(
    private readonly ctx: BlockContext,
    private readonly o: RunOptions,
  ) {}

  /** Loads the sidecar and declares the output at the board's rate and channel count. */
  async load(params: Record<string, unknown>): Promise<void> {
    const ctx = this.ctx;
    const link = await loadBoard(ctx, params, this.o.kinds.length, {
      result: (v) => this.onResult(v),
      error: (e) => this.onError(e),
      status: (s, m) => this.onStatus(s, m),
      output: (line) => this.onOutput(line),
    });
    this.link = link;
    this.out = ctx.output(vectorShape(link.channels), "data");
    if (ctx.declaredRate === undefined) ctx.setDesiredRate(link.rate);
    this.clock = new DeviceClock(link.rate, 0.5, 1 / this.o.pollRate);
    this.names = channelNames(this.o.kinds, link.kindCounts);
    this.timer = ctx.every(this.o.pollRate, () => this.poll(), { catchUp: "skip" });
    this.refresh();
  }

  private get sidecar(): PythonSidecar {
    return this.link!.sidecar;
  }

  instance(): BlockInstance {
    return {
      start: () => this.start(),
      stop: () => this.stop(),
      reset: () => {
        this.emitted = 0;
        this.clock!.reset();
        this.throttle.reset();
        this.refresh();
      },
      dispose: () => {
        this.running = false;
        this.sidecar.close();
      },
      actions: {
        channels: {
          label: "Channels",
          description: "The kind of each output channel",
          run: () => this.names.join(", "),
        },
        counts: {
          label: "Counts",
          description: "Samples, lost samples, reconnections, failed attempts, sidecar restarts",
          run: () => this.countsText(),
        },
      },
    };
  }

  private start(): void {
    this.running = true;
    this.clock!.restart();
    this.timer!.start();
    if (this.ctx.virtual) this.ctx.warn(VIRTUAL_WARNING);
    this.refresh();
  }

  private stop(): void {
    this.running = false;
    this.timer!.stop();
    if (this.sidecar.ready) this.sidecar.call(new Float64Array([CMD_STOP]));
    this.inFlight = false;
    this.awaiting();
  }

  /** One poll at a time: ticks while one is out are skipped (the samples wait in the sidecar). */
  private poll(): void {
    const sc = this.sidecar;
    if (this.inFlight || !this.running || !sc.ready) return;
    if (sc.call(new Float64Array([CMD_POLL])) >= 0) {
      this.inFlight = true;
      this.awaiting();
    }
  }

  /** Under the virtual clock the engine waits for the poll in flight. */
  private awaiting(): void {
    if (this.ctx.virtual) this.ctx.setAwaiting(this.inFlight ? 1 : 0);
  }

  private onResult(values: Float64Array): void {
    this.inFlight = false;
    this.awaiting();
    readCounts(values, this.counts);
    this.noteCounts();
    const n = values[H_N]!;
    if (n > 0 && this.running) this.emitRows(values, n);
    if (this.counts.state === BoardState.Ended && this.o.playback && !this.finished) {
      this.finished = true;
      this.ctx.finish();
    }
    if (this.throttle.due(this.ctx.now()) || n === 0) this.refresh();
  }

  /** Reconnections re-anchor the sample clock; new lost samples are warned (rate-limited). */
  private noteCounts(): void {
    const c = this.counts;
    if (c.reconnects !== this.lastReconnects) {
      this.lastReconnects = c.reconnects;
      this.clock!.restart();
      this.ctx.warn(`${this.o.target}: streaming again after a failure`);
    }
    if (c.lost > this.lastLost) {
      const now = this.ctx.now();
      if (now - this.lastWarn >= WARN_EVERY_S) {
        this.lastWarn = now;
        const k = c.lost - this.lastLost;
        this.ctx.warn(`${this.o.target}: ${k} samples lost (gaps in its package numbers)`);
      }
      this.lastLost = c.lost;
    }
  }

  /** Rows 1…n of the result (each `width` wide, the channels first) as one frame. */
  private emitRows(values: Float64Array, n: number): void {
    const { channels: c, width: w } = this.link!;
    const f = this.out!.frame(n);
    this.clock!.stamp(this.ctx.now(), f.t, n);
    for (let i = 0; i < n; i++) {
      const row = (i + 1) * w;
      f.v.set(values.subarray(row, row + c), i * f.stride);
    }
    this.out!.emit(f);
    this.emitted += n;
  }

  private onError(e: PythonCallError): void {
    this.inFlight = false;
    this.awaiting();
    if (e.kind === "crash" || e.kind === "timeout") return; // the restart reports it
    this.lastFailure = failureText(e.message);
    // The module raises its own sentences: the traceback says nothing more (others keep it).
    const detail = e.message === this.lastFailure ? e.traceback : undefined;
    this.ctx.error(`BrainFlow: ${this.lastFailure}`, detail);
    this.refresh();
  }

  private onStatus(s: string, message?: string): void {
    if (!this.link) return; // the load itself: its outcome is what loadBoard returns
    if (s === "restarting") {
      if (!this.sidecarDown) {
        this.restarts++;
        this.ctx.error(`BrainFlow: ${message ?? "the Python sidecar stopped"}; restarting it`);
      }
      this.sidecarDown = message ?? "the Python sidecar stopped; restarting";
      this.inFlight = false;
      this.clock!.restart();
      this.awaiting();
    } else if (s === "ready") {
      this.sidecarDown = "";
    }
    this.refresh();
  }

  /** BrainFlow's own log lines (LogLevel), as warnings (rate-limited). */
  private onOutput(line: string): void {
    const now = this.ctx.now();
    if (now - this.lastWarn < WARN_EVERY_S) return;
    this.lastWarn = now;
    this.ctx.warn(`BrainFlow: ${line}`);
  }

  private refresh(): void {
    const c = this.counts;
    let text = this.sidecarDown || stateText(c, this.o.target, this.lastFailure);
    text += ` · ${plural(this.emitted, "sample")}`;
    const pid = this.link?.sidecar.pid;
    if (pid !== undefined) text += ` · pid ${pid}`;
    if (c.lost > 0) text += ` · ${c.lost} lost (package numbers)`;
    if (c.reconnects > 0) text += ` · reconnected ${c.reconnects}×`;
    if (this.restarts > 0) text += ` · sidecar restarted ${this.restarts}×`;
    if (text !== this.lastText) {
      this.lastText = text;
      this.ctx.setText(text);
    }
  }

  private countsText(): string {
    const c = this.counts;
    return (
      `${this.emitted} samples emitted (${c.total} read by this sidecar), ${c.lost} lost, ` +
      `${c.reconnects} reconnections, ${c.failures} failed attempts, ` +
      `${this.restarts} sidecar restarts` +
      (this.lastFailure ? `; last failure: ${this.lastFailure}` : "")
    );
  }
}
