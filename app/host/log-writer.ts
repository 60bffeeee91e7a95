/**
 * Writes `Path` logs (and Logger files) on the host's main thread, off every engine worker's hot
 * path: workers copy raw events into SAB rings; this drains them every `intervalMs`, formats
 * `timestamp,v1,…,vn` lines and appends them to the files. Data reaches the disk at least once a
 * second, and rings live in shared memory, so a crashed worker loses nothing already written.
 */
import { closeSync, mkdirSync, openSync, writeSync } from "node:fs";
import { dirname, isAbsolute, resolve } from "node:path";
import { Frame, type Shape } from "../engine/frame";
import { formatLogLine, logFileName } from "../engine/runtime/logsink";
import { SabRing, type SabRingInit } from "../engine/runtime/sab-ring";

interface OpenLog {
  key: string;
  file: string;
  fd: number;
  ring: SabRing;
  frame: Frame;
  lines: number;
  droppedReported: number;
  closing: boolean;
}

export interface LogWriterEvents {
  onError(file: string, message: string): void;
}

export class LogWriter {
  private readonly logs = new Map<string, OpenLog>();
  private timer: NodeJS.Timeout | undefined;

  constructor(
    private readonly baseDir: string,
    private readonly events: LogWriterEvents,
    private readonly intervalMs = 100,
  ) {}

  private readonly opened: string[] = [];

  /** Every file opened so far (also after closing). */
  get files(): string[] {
    return [...this.opened];
  }

  /** Opens (truncates) the file for one log ring. `key` must be unique per ring. */
  open(
    key: string,
    block: string,
    port: string,
    isDefaultPort: boolean,
    path: string,
    shape: Shape,
    ring: SabRingInit,
  ): string {
    const rel = logFileName(path, block, port, isDefaultPort);
    const file = isAbsolute(rel) ? rel : resolve(this.baseDir, rel);
    try {
      mkdirSync(dirname(file), { recursive: true });
      const fd = openSync(file, "w");
      this.opened.push(file);
      this.logs.set(key, {
        key,
        file,
        fd,
        ring: new SabRing(ring),
        frame: new Frame(shape, 4096),
        lines: 0,
        droppedReported: 0,
        closing: false,
      });
    } catch (e) {
      this.events.onError(file, `cannot open log file: ${(e as Error).message}`);
    }
    if (!this.timer) {
      this.timer = setInterval(() => this.drainAll(), this.intervalMs);
    }
    return file;
  }

  /** Drains, writes and closes one log. */
  close(key: string): void {
    const l = this.logs.get(key);
    if (!l) return;
    this.drain(l);
    this.finish(l);
  }

  /** Drains every ring now (also called on a timer). */
  drainAll(): void {
    for (const l of this.logs.values()) this.drain(l);
  }

  /** Drains and closes everything. */
  closeAll(): void {
    for (const l of [...this.logs.values()]) {
      this.drain(l);
      this.finish(l);
    }
    if (this.timer) clearInterval(this.timer);
    this.timer = undefined;
  }

  linesWritten(file: string): number {
    for (const l of this.logs.values()) if (l.file === file) return l.lines;
    return 0;
  }

  private finish(l: OpenLog): void {
    try {
      closeSync(l.fd);
    } catch {
      // already closed
    }
    this.logs.delete(l.key);
  }

  private drain(l: OpenLog): void {
    const f = l.frame;
    for (;;) {
      const n = l.ring.read(f, 4096);
      if (n === 0) break;
      let chunk = "";
      for (let i = 0; i < n; i++)
        chunk += formatLogLine(f.t[i]!, f.v, i * f.stride, f.stride) + "\n";
      try {
        writeSync(l.fd, chunk);
        l.lines += n;
      } catch (e) {
        this.events.onError(l.file, `cannot write: ${(e as Error).message}`);
        break;
      }
    }
    const dropped = l.ring.dropped;
    if (dropped > l.droppedReported) {
      this.events.onError(
        l.file,
        `the log could not keep up and lost ${dropped - l.droppedReported} events (${dropped} in all); the disk may be too slow`,
      );
      l.droppedReported = dropped;
    }
  }
}
