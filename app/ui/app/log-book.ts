/**
 * The event log's one source of truth: entries grouped by load. A load (or a pipeline adopted
 * from a shared engine) starts a new section holding the load's own diagnostics; runtime events
 * and the replies to actions join the current section. The counts are the current section's, so
 * they reset with every load and always match what the Log lists for it. Framework-free.
 */
import type { Diagnostic } from "../../engine/diagnostics";

export type LogLevel = "error" | "warning" | "info";

export interface LogEntry {
  id: number;
  /** UNIX seconds. */
  t: number;
  level: LogLevel;
  block: string;
  message: string;
}

export interface LogBook {
  entries: readonly LogEntry[];
  /** Entries with an id at least this belong to the current load (0: all of them). */
  currentFrom: number;
}

export interface LogCounts {
  errors: number;
  warnings: number;
  /** Informational lines (a diagnostic of severity info counts here, like replies). */
  infos: number;
}

export const EMPTY_LOG: LogBook = { entries: [], currentFrom: 0 };

/** The most entries kept (the oldest go first; the current load's too when it alone is longer). */
export const MAX_LOG = 500;

const keepLast = (entries: readonly LogEntry[]): readonly LogEntry[] =>
  entries.length > MAX_LOG ? entries.slice(entries.length - MAX_LOG) : entries;

/** Adds entries to the current load's section. */
export function appendEntries(book: LogBook, added: readonly LogEntry[]): LogBook {
  if (added.length === 0) return book;
  return { ...book, entries: keepLast([...book.entries, ...added]) };
}

/** Starts a new load's section with `first` (the load's own lines, ids increasing). */
export function startLoad(book: LogBook, first: readonly LogEntry[], nextId: number): LogBook {
  const from = first.length > 0 ? first[0]!.id : nextId;
  return { entries: keepLast([...book.entries, ...first]), currentFrom: from };
}

/** The current load's entries, oldest first. */
export function currentEntries(book: LogBook): readonly LogEntry[] {
  return book.entries.filter((e) => e.id >= book.currentFrom);
}

/** The entries of earlier loads, oldest first. */
export function earlierEntries(book: LogBook): readonly LogEntry[] {
  return book.entries.filter((e) => e.id < book.currentFrom);
}

export function countLevels(entries: readonly { level: LogLevel }[]): LogCounts {
  const c: LogCounts = { errors: 0, warnings: 0, infos: 0 };
  for (const e of entries) {
    if (e.level === "error") c.errors++;
    else if (e.level === "warning") c.warnings++;
    else c.infos++;
  }
  return c;
}

/** The counts of the current load. */
export function currentCounts(book: LogBook): LogCounts {
  return countLevels(currentEntries(book));
}

/** "1 warning", "3 errors". */
export const plural = (n: number, what: string): string => `${n} ${what}${n === 1 ? "" : "s"}`;

/**
 * The counts as words: "2 errors, 8 warnings", "8 warnings", "1 error"; "no errors or warnings"
 * only when there are neither.
 */
export function countsText(c: LogCounts): string {
  const parts = [
    ...(c.errors > 0 ? [plural(c.errors, "error")] : []),
    ...(c.warnings > 0 ? [plural(c.warnings, "warning")] : []),
  ];
  return parts.length > 0 ? parts.join(", ") : "no errors or warnings";
}

const LEVEL_OF: Record<Diagnostic["severity"], LogLevel> = {
  error: "error",
  warning: "warning",
  info: "info",
};

/** "demo.yaml" for "pipelines/demo.yaml" (the Log's narrow column; the banner has the path). */
const baseName = (file: string): string => file.split(/[/\\]/).pop() || file;

/** A diagnostic as one line of the log: where (file:line:col) and what, as the banner says it. */
export function diagnosticLine(d: Diagnostic): { level: LogLevel; block: string; message: string } {
  const file = baseName(d.file);
  const where = d.line > 0 ? `${file}:${d.line}:${d.col}` : file;
  let message = d.message;
  if (d.expected !== undefined) message += ` (expected ${d.expected})`;
  if (d.suggestion !== undefined) message += `; did you mean '${d.suggestion}'?`;
  return { level: LEVEL_OF[d.severity], block: where, message };
}

/** What a load reported, for the log: the file, its diagnostics, a problem outside the file. */
export interface LoadReport {
  file: string;
  diagnostics: readonly Diagnostic[];
  /** A problem that is not in the file (network, engine), or undefined. */
  error?: string;
  /** Shown, not loaded here: a shared engine's pipeline loaded by another client. */
  adopted?: boolean;
  /** True when the load replaced what ran (a new section); false: a failed attempt only. */
  replaced: boolean;
}

/** The log lines of a load: a heading line, then one line per diagnostic and the error. */
export function loadLines(r: LoadReport): { level: LogLevel; block: string; message: string }[] {
  const counts = countLevels(r.diagnostics.map((d) => ({ level: LEVEL_OF[d.severity] })));
  if (r.error !== undefined) counts.errors++;
  const failed = counts.errors > 0;
  const what = r.adopted
    ? `showing ${r.file} (loaded by another client of this engine)`
    : failed
      ? `${r.file} did not load`
      : `loaded ${r.file}`;
  const head = { level: "info" as const, block: "", message: `${what}: ${countsText(counts)}` };
  const lines = r.diagnostics.map(diagnosticLine);
  if (r.error !== undefined) lines.push({ level: "error", block: r.file, message: r.error });
  return [head, ...lines];
}

/**
 * The whole log (earlier loads and the current one, oldest first) as JSON Lines, for the Log's
 * download: one object per entry with its ISO time, UNIX seconds, level, block, message and
 * whether it belongs to the current load.
 */
export function logJsonLines(book: LogBook): string {
  return book.entries
    .map(
      (e) =>
        JSON.stringify({
          time: new Date(e.t * 1000).toISOString(),
          t: e.t,
          level: e.level,
          block: e.block,
          message: e.message,
          currentLoad: e.id >= book.currentFrom,
        }) + "\n",
    )
    .join("");
}

/** The download's file name: mosaic-log-20260124-153005.jsonl (local time). */
export function logFileName(at: Date): string {
  const p = (n: number) => String(n).padStart(2, "0");
  const day = `${at.getFullYear()}${p(at.getMonth() + 1)}${p(at.getDate())}`;
  return `mosaic-log-${day}-${p(at.getHours())}${p(at.getMinutes())}${p(at.getSeconds())}.jsonl`;
}
