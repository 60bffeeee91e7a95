/**
 * Writes `Path` logs (and Logger files) on the host's main thread, off every engine worker's hot
 * path: workers copy raw events into SAB rings; this drains them every `intervalMs`, formats
 * `timestamp,v1,…,vn` lines and appends them to the files. Data reaches the disk at least once a
 * second, and rings live in shared memory, so a crashed worker loses nothing already written.
 *
 * Nothing is lost without being counted, and nothing is reported twice:
 * - **One writer per file.** A log whose file another open log already writes — in this writer or
 *   any other in the process (two pipelines of `mosaic serve`), by whatever name (a relative and
 *   an absolute path, a link, a Logger's file and a block's `Path`) — is refused with one error
 *   naming both, and its events are counted as lost instead of tearing the other's lines (the
 *   loader refuses the cases a file's text shows: app/engine/pipeline/paths.ts).
 * - **A write that fails** (a full disk, `/dev/full`) is one error; from then on every event taken
 *   from the ring is counted as lost, the events of the failed write included, and writing is
 *   tried again every RETRY_S (a partial line is cut off first, so the file never holds a torn
 *   line). Getting going again, and every RETRY_S while events are lost, is not reported again;
 *   closing reports how many were lost in all.
 * - **A full ring** (the writer could not keep up) is one error when it first drops, and counted.
 * `stats()` gives every log's lines, losses and error, for a status display. The rings keep
 * draining whatever happens, so a producer under the virtual clock (which waits for room) never
 * hangs on a log that cannot be written.
 */
import {
  closeSync,
  fstatSync,
  ftruncateSync,
  mkdirSync,
  openSync,
  statSync,
  writeSync,
  type Stats,
} from "node:fs";
import { dirname, isAbsolute, resolve } from "node:path";
import { Frame, type Shape } from "../engine/frame";
import { formatLogLine, logFileName } from "../engine/runtime/logsink";
import { SabRing, type SabRingInit } from "../engine/runtime/sab-ring";

/** How often a log whose write failed tries again, s. */
export const RETRY_S = 5;

interface OpenLog {
  key: string;
  /** The block (or the Logger's stream) whose events this log holds. */
  block: string;
  file: string;
  /** -1 when the file could not be opened or was refused. */
  fd: number;
  /** `dev:ino` of a regular file while this log writes it. */
  identity: string | undefined;
  /** Regular file: writes go at `bytes` (the end of the last whole line). */
  regular: boolean;
  bytes: number;
  ring: SabRing;
  frame: Frame;
  lines: number;
  /** Events taken from the ring and not written (a failed write, a refused or unopened file). */
  lost: number;
  droppedReported: number;
  /** Why the log is not being written (undefined while it is). */
  error: string | undefined;
  /** When a failed write is tried again (performance.now() ms); Infinity: never. */
  retryAt: number;
}

export interface LogWriterEvents {
  onError(file: string, message: string): void;
}

/** What `stats()` says about one log. */
export interface LogStats {
  key: string;
  block: string;
  file: string;
  lines: number;
  /** Events not written: failed writes, a refused file, and events the ring could not hold. */
  lost: number;
  /** Why the log is not being written, if it is not. */
  error: string | undefined;
}

/** Regular files open for writing by any LogWriter of this process, by `dev:ino`. */
const writing = new Map<string, { block: string; file: string }>();

const identityOf = (st: { dev: number; ino: number }): string => `${st.dev}:${st.ino}`;

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

  /**
   * Opens (truncates) the file for one log ring. `key` must be unique per ring. A file that
   * cannot be opened, or that another open log writes, is one error; the ring is still drained
   * (its events counted as lost).
   */
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
    const l = newLog(key, block, file, shape, ring);
    this.logs.set(key, l);
    this.openFile(l);
    if (!this.timer) {
      this.timer = setInterval(() => this.drainAll(), this.intervalMs);
    }
    return file;
  }

  /** Opens the log's file unless another log writes it; either failure is the log's error. */
  private openFile(l: OpenLog): void {
    const { block, file } = l;
    try {
      mkdirSync(dirname(file), { recursive: true });
      // Refused before opening: opening truncates, and the other log's lines would go.
      const before = statOrUndefined(file);
      const other = before?.isFile() ? writing.get(identityOf(before)) : undefined;
      if (other) this.refuse(l, sharedFileMessage(block, file, other));
      else this.startWriting(l);
    } catch (e) {
      this.refuse(
        l,
        `cannot open log file: ${(e as Error).message} (the log of '${block}' is lost)`,
      );
    }
  }

  /** Opens (truncates) the log's file and, for a regular file, claims it for this log. */
  private startWriting(l: OpenLog): void {
    const fd = openSync(l.file, "w");
    const st = fstatSync(fd);
    l.fd = fd;
    l.regular = st.isFile();
    if (l.regular) {
      l.identity = identityOf(st);
      writing.set(l.identity, { block: l.block, file: l.file });
    }
    this.opened.push(l.file);
  }

  /** The log is not written, for `message`: one error. */
  private refuse(l: OpenLog, message: string): void {
    l.error = message;
    this.events.onError(l.file, message);
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

  /** Every open log: lines written, events lost, the error that stops it. */
  stats(): LogStats[] {
    return [...this.logs.values()].map((l) => ({
      key: l.key,
      block: l.block,
      file: l.file,
      lines: l.lines,
      lost: l.lost + l.ring.dropped,
      error: l.error,
    }));
  }

  private finish(l: OpenLog): void {
    if (l.fd >= 0) {
      try {
        closeSync(l.fd);
      } catch {
        // already closed
      }
    }
    if (l.identity !== undefined) writing.delete(l.identity);
    this.logs.delete(l.key);
    const lost = l.lost + l.ring.dropped;
    if (lost > 0) {
      this.events.onError(
        l.file,
        `the log of '${l.block}' lost ${lost} event${lost === 1 ? "" : "s"} in all ` +
          `(${l.lines} line${l.lines === 1 ? "" : "s"} written)`,
      );
    }
  }

  /**
   * Writes `buf` whole at the log's position. Returns the lines written before a failure (the
   * partial line cut off again), or -1 when all went.
   */
  private write(l: OpenLog, buf: Buffer): number {
    let done = 0;
    try {
      while (done < buf.length) {
        const n = writeSync(l.fd, buf, done, buf.length - done, l.regular ? l.bytes + done : null);
        if (n <= 0) throw new Error("nothing was written");
        done += n;
      }
      l.bytes += done;
      return -1;
    } catch (e) {
      // Keep the whole lines that went; cut the torn one off (best effort).
      const whole = done > 0 ? buf.lastIndexOf(10, done - 1) + 1 : 0;
      let lines = 0;
      for (let i = 0; i < whole; i++) if (buf[i] === 10) lines++;
      l.bytes += whole;
      if (l.regular && whole < done) {
        try {
          ftruncateSync(l.fd, l.bytes);
        } catch {
          // the file keeps a partial last line
        }
      }
      if (l.error === undefined) {
        l.error = `cannot write: ${(e as Error).message}`;
        this.events.onError(
          l.file,
          `${l.error}; the log of '${l.block}' counts its events as lost until a write ` +
            `succeeds again (tried every ${RETRY_S} s)`,
        );
      }
      l.retryAt = performance.now() + RETRY_S * 1000;
      return lines;
    }
  }

  private drain(l: OpenLog): void {
    const f = l.frame;
    for (;;) {
      const n = l.ring.read(f, 4096);
      if (n === 0) break;
      // Not written: refused or unopened (for good), or failing until the next try.
      if (l.fd < 0 || (l.error !== undefined && performance.now() < l.retryAt)) {
        l.lost += n;
        continue;
      }
      let chunk = "";
      for (let i = 0; i < n; i++)
        chunk += formatLogLine(f.t[i]!, f.v, i * f.stride, f.stride) + "\n";
      const wrote = this.write(l, Buffer.from(chunk));
      if (wrote < 0) {
        l.lines += n;
        l.error = undefined;
        l.retryAt = Infinity;
      } else {
        l.lines += wrote;
        l.lost += n - wrote;
      }
    }
    const dropped = l.ring.dropped;
    if (dropped > l.droppedReported) {
      if (l.droppedReported === 0) {
        this.events.onError(
          l.file,
          `the log of '${l.block}' could not keep up and lost ${dropped} events; the disk may be ` +
            "too slow (further losses are counted, and reported when the log closes)",
        );
      }
      l.droppedReported = dropped;
    }
  }
}

/** A log of `block` into `file`, not yet open. */
function newLog(
  key: string,
  block: string,
  file: string,
  shape: Shape,
  ring: SabRingInit,
): OpenLog {
  return {
    key,
    block,
    file,
    fd: -1,
    identity: undefined,
    regular: false,
    bytes: 0,
    ring: new SabRing(ring),
    frame: new Frame(shape, 4096),
    lines: 0,
    lost: 0,
    droppedReported: 0,
    error: undefined,
    retryAt: Infinity,
  };
}

/** The error of a log refused because `other` already writes its file. */
function sharedFileMessage(
  block: string,
  file: string,
  other: { block: string; file: string },
): string {
  return (
    `the log of '${block}' cannot be written: ${file} is already written by the log of ` +
    `'${other.block}'${other.file !== file ? ` (as ${other.file})` : ""}; two writers ` +
    "on one file tear and lose lines: give one of them another Path (its events are " +
    "counted as lost)"
  );
}

function statOrUndefined(file: string): Stats | undefined {
  try {
    return statSync(file);
  } catch {
    return undefined;
  }
}
