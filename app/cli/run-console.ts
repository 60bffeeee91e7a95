/**
 * What `mosaic run` shows while a pipeline runs and when it stops: on a terminal the live
 * per-block table (redrawn in place) with events and failures above it; with `--json` one JSON
 * object per line (telemetry, events, `warmup-done`, `fatal`, the final summary); otherwise the
 * events and, at the end, the table once. Also why the run stopped and its exit code: 1 after a
 * fatal error or a block's error, 0 otherwise.
 */
import type { HostEvents } from "../host/host";
import type { RuntimeEvent, Telemetry } from "../engine/runtime/runtime";
import { renderTable } from "./table";

/** Why a run stopped: its input ended, its duration, Ctrl-C (or SIGTERM), a fatal error. */
export type StopReason = "finished" | "duration" | "interrupted" | "fatal";

/** How a run went, for its summary. */
export interface RunEnd {
  reason: StopReason;
  wallSeconds: number;
  measuredSeconds: number;
  /** The `Path` logs written. */
  logs: string[];
  /** The run had a virtual clock and a `--duration` (its end is that duration's). */
  virtualDuration: boolean;
}

type Print = (line: string) => void;

export class RunConsole {
  private readonly tty: boolean;
  private readonly color: boolean;
  private latest: Telemetry | undefined;
  /** Lines of the table on the terminal now (0: none, or events were written below it). */
  private drawn = 0;
  private fatal = false;
  private blockErrors = 0;
  private resolveStop: (reason: StopReason) => void = () => undefined;
  /** Why the run stopped, once it has (the first reason given). */
  readonly stopped: Promise<StopReason>;

  constructor(
    private readonly json: boolean,
    private readonly out: Print,
    private readonly err: Print,
  ) {
    this.tty = process.stdout.isTTY === true && !json;
    this.color = this.tty && !process.env.NO_COLOR;
    this.stopped = new Promise<StopReason>((r) => (this.resolveStop = r));
  }

  /** Ends the run (the first reason given is the one kept). */
  stop(reason: StopReason): void {
    this.resolveStop(reason);
  }

  /**
   * The host's callbacks, only those used: the JSON lines (printed as the workers encoded them),
   * or the objects for the live table on a terminal.
   */
  events(): HostEvents {
    return {
      ...(this.json ? { telemetryLine: (line: string) => this.out(line) } : {}),
      ...(this.tty ? { telemetry: (t: Telemetry) => (this.latest = t) } : {}),
      event: (e) => this.event(e),
      finished: () => this.stop("finished"),
      fatal: (m) => this.failed(m),
    };
  }

  /** Redraws the live table four times a second, on a terminal (undefined: not one). */
  startRedrawing(): NodeJS.Timeout | undefined {
    return this.tty ? setInterval(() => this.draw(), 250) : undefined;
  }

  /** The timing statistics were reset after `--warmup`. */
  warmupDone(): void {
    if (this.json) this.out(JSON.stringify({ type: "warmup-done", t: Date.now() / 1000 }));
  }

  /** Prints the run's end (`final`: the last telemetry) and returns the exit code. */
  finish(final: Telemetry, end: RunEnd): number {
    this.latest = final;
    const code = this.fatal ? 1 : this.blockErrors > 0 ? 1 : 0;
    if (this.json) {
      const { reason, wallSeconds, measuredSeconds, logs } = end;
      this.out(
        JSON.stringify({
          type: "summary",
          reason,
          exitCode: code,
          wallSeconds,
          measuredSeconds,
          logs,
          ...final,
        }),
      );
    } else {
      if (this.tty) this.draw();
      else for (const l of renderTable(final, { color: false })) this.out(l);
      for (const l of summaryLines(final)) this.out(l);
      this.out(`stopped: ${stopWords(end)}${this.errorsNote()}`);
    }
    return code;
  }

  private draw(): void {
    if (!this.latest || !this.tty) return;
    const lines = renderTable(this.latest, {
      color: this.color,
      width: process.stdout.columns || 120,
    });
    let s = this.drawn > 0 ? `\x1b[${this.drawn}F` : "";
    for (const l of lines) s += `\x1b[2K${l}\n`;
    process.stdout.write(s);
    this.drawn = lines.length;
  }

  private event(e: RuntimeEvent): void {
    if (e.level === "error") this.blockErrors++;
    if (this.json) this.out(JSON.stringify({ type: "event", ...e }));
    else {
      // The event goes where the table was; the table is drawn again below it.
      if (this.tty && this.drawn > 0) {
        process.stdout.write(`\x1b[${this.drawn}F\x1b[J`);
        this.drawn = 0;
      }
      this.err(`${e.level}: ${e.block}: ${e.message}`);
    }
  }

  private failed(message: string): void {
    this.fatal = true;
    if (this.json) this.out(JSON.stringify({ type: "fatal", message }));
    else this.err(`fatal: ${message}`);
    this.stop("fatal");
  }

  /** `; N block errors (see above)` when blocks reported errors. */
  private errorsNote(): string {
    const n = this.blockErrors;
    return n ? `; ${n} block error${n === 1 ? "" : "s"} (see above)` : "";
  }
}

/** Why the run stopped, in the words of its last line. */
function stopWords(end: RunEnd): string {
  switch (end.reason) {
    case "finished":
      return end.virtualDuration ? "virtual duration reached" : "input exhausted";
    case "duration":
      return "duration reached";
    case "interrupted":
      return "interrupted";
    default:
      return "failed";
  }
}

/** The timers' and the delivery delays' summary lines, after the final table. */
function summaryLines(t: Telemetry): string[] {
  const lines: string[] = [];
  const ms = (x: number): string => (x < 1 ? x.toFixed(3) : x.toFixed(2));
  for (const b of t.blocks) {
    if (b.timer && b.timer.fired > 0 && b.timer.latenessP50Us === b.timer.latenessP50Us) {
      const missed =
        b.timer.catchUp === "skip" ? `${b.timer.missed} skipped (CatchUp: skip)` : "none lost";
      lines.push(
        `${b.name}: ${b.timer.fired} ticks (${missed}), batching ${b.timer.batchingMs} ms, wake-up lateness p50 ${b.timer.latenessP50Us} µs, p99 ${b.timer.latenessP99Us} µs, max ${Math.round(b.timer.latenessMaxUs)} µs`,
      );
    }
  }
  const delayed = t.blocks.filter((b) => b.delay.n > 0);
  if (delayed.length > 0) {
    const worst = delayed.reduce((a, b) => (b.delay.p99Ms > a.delay.p99Ms ? b : a));
    lines.push(
      `delivery delay (processing − event time): worst p99 ${ms(worst.delay.p99Ms)} ms (${worst.name}), max ${ms(Math.max(...delayed.map((b) => b.delay.maxMs)))} ms`,
    );
  }
  return lines;
}
