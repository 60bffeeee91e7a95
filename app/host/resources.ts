import { realpathSync } from "node:fs";
import { mkdir, readFile, rename, rm, writeFile } from "node:fs/promises";
import { basename, dirname, isAbsolute, relative, resolve, sep } from "node:path";
import type { Resources } from "../engine/block";
import { openFileRead } from "./file-read";
import { openFileWrite } from "./file-write";

/**
 * Writes by file. Writes to one file never overlap (two overlapping `writeFile`s to the same
 * path can leave the tail of the longer text behind the shorter one), and while one is in
 * flight only the newest waiting text is kept: a model saved ten times in a burst is written at
 * most twice, the last time with the last text.
 */
interface FileQueue {
  running: Promise<void>;
  next?: { text: string; waiters: { resolve(): void; reject(e: unknown): void }[] };
}
const queues = new Map<string, FileQueue>();
let tmpSeq = 0;

/** Writes `text` to `full` atomically: a temporary file beside it, then a rename. */
async function writeAtomic(full: string, text: string): Promise<void> {
  await mkdir(dirname(full), { recursive: true });
  const tmp = `${full}.${process.pid}.${tmpSeq++}.tmp`;
  try {
    await writeFile(tmp, text, "utf8");
    await rename(tmp, full);
  } catch (e) {
    await rm(tmp, { force: true }).catch(() => {});
    throw e;
  }
}

function enqueue(full: string, text: string): Promise<void> {
  const q = queues.get(full);
  if (q) {
    return new Promise<void>((resolve, reject) => {
      const waiters = q.next?.waiters ?? [];
      waiters.push({ resolve, reject });
      q.next = { text, waiters };
    });
  }
  const entry: FileQueue = { running: Promise.resolve() };
  queues.set(full, entry);
  const run = async (t: string): Promise<void> => {
    try {
      await writeAtomic(full, t);
    } finally {
      const next = entry.next;
      entry.next = undefined;
      if (next) {
        entry.running = run(next.text).then(
          () => next.waiters.forEach((w) => w.resolve()),
          (e: unknown) => next.waiters.forEach((w) => w.reject(e)),
        );
      } else {
        queues.delete(full);
      }
    }
  };
  entry.running = run(text);
  return entry.running;
}

/** Resolves when every write started so far (and the ones they queued) has finished. */
export async function flushWrites(): Promise<void> {
  while (queues.size > 0) {
    await Promise.allSettled([...queues.values()].map((q) => q.running));
  }
}

/**
 * `full` as it is on disk: symbolic links resolved, for the part that exists (a file about to be
 * written, in folders about to be made, keeps the rest of its name).
 */
function onDisk(full: string): string {
  let head = full;
  const rest: string[] = [];
  for (;;) {
    try {
      return resolve(realpathSync(head), ...rest);
    } catch {
      const up = dirname(head);
      if (up === head) return full;
      rest.unshift(basename(head));
      head = up;
    }
  }
}

/**
 * Folders a pipeline may read and write (app/host/session-hub.ts: pipelines loaded by clients of
 * `mosaic serve` and of the desktop app). `check(full)` returns the sentence that refuses a path
 * outside all of them (symbolic links followed), or undefined.
 */
export class AllowedFolders {
  private readonly real: string[];
  constructor(readonly dirs: readonly string[]) {
    this.real = dirs.map((d) => onDisk(resolve(d)));
  }

  check(full: string, what = "use"): string | undefined {
    const real = onDisk(full);
    for (const root of this.real) {
      const rel = relative(root, real);
      if (rel === "" || (rel !== ".." && !rel.startsWith(`..${sep}`) && !isAbsolute(rel))) {
        return undefined;
      }
    }
    return (
      `${full} is outside the folders this pipeline may ${what} (${this.dirs.join(", ")}): a ` +
      "pipeline loaded by a client of `mosaic serve` or by the desktop app's window reads and " +
      "writes only in its own folder and the data folder (`mosaic serve --data-dir DIR`)"
    );
  }
}

/**
 * File access for blocks: relative paths are resolved against the pipeline file's folder. With
 * `allowed`, every path must lie in one of those folders (see AllowedFolders).
 */
export function nodeResources(baseDir: string, allowed?: AllowedFolders): Resources {
  const confine = (p: string, what: string): string => {
    const full = isAbsolute(p) ? p : resolve(baseDir, p);
    const refused = allowed?.check(full, what);
    if (refused !== undefined) throw new Error(refused);
    return full;
  };
  return {
    confined: allowed !== undefined,
    resolve: (p: string) => confine(p, "use"),
    readText: async (p: string) => {
      const full = confine(p, "read");
      try {
        return await readFile(full, "utf8");
      } catch (e) {
        const code = (e as NodeJS.ErrnoException).code;
        if (code === "ENOENT") throw new Error(`file not found: ${full}`);
        if (code === "EACCES") throw new Error(`no permission to read ${full}`);
        if (code === "EISDIR") throw new Error(`${full} is a folder, not a file`);
        throw new Error(`cannot read ${full}: ${(e as Error).message}`);
      }
    },
    openRead: (p: string) => openFileRead(confine(p, "read")),
    openWrite: (p: string, o?: { overwrite?: boolean }) => openFileWrite(confine(p, "write"), o),
    writeText: async (p: string, text: string) => {
      const full = confine(p, "write");
      try {
        await enqueue(full, text);
      } catch (e) {
        const code = (e as NodeJS.ErrnoException).code;
        if (code === "EACCES") throw new Error(`no permission to write ${full}`);
        if (code === "ENOSPC") throw new Error(`the disk is full: cannot write ${full}`);
        throw new Error(`cannot write ${full}: ${(e as Error).message}`);
      }
    },
  };
}
