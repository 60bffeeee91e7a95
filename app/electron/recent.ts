/**
 * The "Open Recent" list: the last pipeline files opened, newest first, without duplicates, at
 * most 10, persisted as JSON in Electron's userData folder. A missing, unreadable or corrupt file
 * gives an empty list (never an error at start-up); entries that are not absolute paths are
 * dropped. Writes go to a temporary file renamed over the old one, so a crash never leaves half a
 * file. Plain Node; the main process passes `join(app.getPath("userData"), RECENT_FILE)`.
 */
import { mkdirSync, readFileSync, renameSync, writeFileSync } from "node:fs";
import { dirname, isAbsolute, normalize } from "node:path";

export const RECENT_FILE = "recent-pipelines.json";
export const RECENT_LIMIT = 10;

export interface RecentOptions {
  limit?: number;
  /** Compare paths ignoring case (Windows, default macOS file systems). */
  caseInsensitive?: boolean;
}

function key(file: string, caseInsensitive: boolean): string {
  const n = normalize(file);
  return caseInsensitive ? n.toLowerCase() : n;
}

/** `list` with `file` in front: earlier entries for the same file removed, cut to the limit. */
export function addRecent(
  list: readonly string[],
  file: string,
  options: RecentOptions = {},
): string[] {
  const limit = options.limit ?? RECENT_LIMIT;
  const ci = options.caseInsensitive ?? false;
  const k = key(file, ci);
  return [normalize(file), ...list.filter((f) => key(f, ci) !== k)].slice(0, limit);
}

/** `list` without `file`. */
export function removeRecent(
  list: readonly string[],
  file: string,
  options: RecentOptions = {},
): string[] {
  const ci = options.caseInsensitive ?? false;
  const k = key(file, ci);
  return list.filter((f) => key(f, ci) !== k);
}

/** Cleans a parsed value: absolute paths only, deduplicated, at most the limit. */
export function sanitizeRecent(value: unknown, options: RecentOptions = {}): string[] {
  const entries = Array.isArray(value)
    ? value
    : value !== null &&
        typeof value === "object" &&
        Array.isArray((value as { files?: unknown }).files)
      ? (value as { files: unknown[] }).files
      : [];
  const out: string[] = [];
  const seen = new Set<string>();
  const ci = options.caseInsensitive ?? false;
  for (const e of entries) {
    if (typeof e !== "string" || e.length === 0 || e.length > 4096 || e.includes("\0")) continue;
    if (!isAbsolute(e)) continue;
    const k = key(e, ci);
    if (seen.has(k)) continue;
    seen.add(k);
    out.push(normalize(e));
    if (out.length >= (options.limit ?? RECENT_LIMIT)) break;
  }
  return out;
}

/** Reads the list; empty when the file is missing, unreadable or not the expected JSON. */
export function loadRecent(storePath: string, options: RecentOptions = {}): string[] {
  let text: string;
  try {
    text = readFileSync(storePath, "utf8");
  } catch {
    return [];
  }
  try {
    return sanitizeRecent(JSON.parse(text), options);
  } catch {
    return [];
  }
}

/** Writes the list (`{ "version": 1, "files": [...] }`), atomically. Throws on I/O errors. */
export function saveRecent(storePath: string, list: readonly string[]): void {
  mkdirSync(dirname(storePath), { recursive: true });
  const tmp = `${storePath}.${process.pid}.tmp`;
  writeFileSync(tmp, JSON.stringify({ version: 1, files: list }, null, 2) + "\n", "utf8");
  renameSync(tmp, storePath);
}

/** The list with its file: what the main process holds. Save errors go to `onError`. */
export class RecentFiles {
  private list: string[];

  constructor(
    private readonly storePath: string,
    private readonly options: RecentOptions & { onError?(message: string): void } = {},
  ) {
    this.list = loadRecent(storePath, options);
  }

  get files(): readonly string[] {
    return this.list;
  }

  add(file: string): void {
    this.update(addRecent(this.list, file, this.options));
  }

  remove(file: string): void {
    this.update(removeRecent(this.list, file, this.options));
  }

  clear(): void {
    this.update([]);
  }

  private update(next: string[]): void {
    this.list = next;
    try {
      saveRecent(this.storePath, next);
    } catch (e) {
      this.options.onError?.(
        `cannot save the recent files list to ${this.storePath}: ${(e as Error).message}`,
      );
    }
  }
}
