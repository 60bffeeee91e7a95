/**
 * Where `Path` logs go. The engine hands raw frames to a LogChannel on the hot path (a copy into
 * a buffer, nothing else); formatting and file writes happen elsewhere (a writer in the host that
 * flushes at least once a second). Line format (DESIGN.md §3): `timestamp,v1,…,vn`, timestamp as
 * UNIX seconds with microseconds, values in shortest round-trip form.
 */
import type { Frame, Shape } from "../frame";

export interface LogChannel {
  write(frame: Frame): void;
  close(): void;
}

export interface LogSink {
  /**
   * Opens the log of `block`'s output `port`. `path` is the block's `Path` as written: a folder
   * (the file is `<folder>/<block>.txt`, or `<block>.<port>.txt` for a non-default port) or, when
   * it ends in a file extension, the file itself.
   */
  open(block: string, port: string, isDefaultPort: boolean, path: string, shape: Shape): LogChannel;
}

/** Formats one event as a log line (without the newline). */
export function formatLogLine(
  t: number,
  v: ArrayLike<number>,
  offset: number,
  count: number,
): string {
  let s = t.toFixed(6);
  for (let k = 0; k < count; k++) s += "," + String(v[offset + k]);
  return s;
}

/** Resolves the log file name for a block's Path (relative to whatever base the sink uses). */
export function logFileName(
  path: string,
  block: string,
  port: string,
  isDefaultPort: boolean,
): string {
  const file = isDefaultPort ? `${block}.txt` : `${block}.${port}.txt`;
  const trimmed = path.replace(/[\\/]+$/, "");
  const endsWithSep = /[\\/]$/.test(path);
  const last = trimmed.split(/[\\/]/).pop() ?? "";
  if (!endsWithSep && /\.[A-Za-z0-9]{1,8}$/.test(last)) {
    return isDefaultPort ? trimmed : trimmed.replace(/(\.[A-Za-z0-9]{1,8})$/, `.${port}$1`);
  }
  return trimmed === "" ? file : `${trimmed}/${file}`;
}

/** A LogSink that keeps lines in memory (tests, browser downloads). */
export class MemoryLogSink implements LogSink {
  readonly files = new Map<string, string[]>();
  open(block: string, port: string, isDefaultPort: boolean, path: string): LogChannel {
    const name = logFileName(path, block, port, isDefaultPort);
    const lines: string[] = this.files.get(name) ?? [];
    this.files.set(name, lines);
    return {
      write(f: Frame) {
        for (let i = 0; i < f.n; i++)
          lines.push(formatLogLine(f.t[i]!, f.v, i * f.stride, f.stride));
      },
      close() {},
    };
  }
  text(name: string): string {
    const l = this.files.get(name);
    return l ? l.join("\n") + (l.length ? "\n" : "") : "";
  }
}
