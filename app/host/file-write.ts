/**
 * `Resources.openWrite` for Node (app/engine/block.ts): a binary file written in pieces,
 * synchronously, by a recorder (XDF, EDF+/BDF). Every `write` goes to the operating system at once
 * (`writeSync`), so what was written survives a kill -9 of the host; `sync` asks the disk to keep
 * it too (fdatasync). An existing file is never replaced unless asked: a recording is not
 * overwritten by accident.
 */
import { closeSync, fdatasyncSync, mkdirSync, openSync, writeSync } from "node:fs";
import { dirname } from "node:path";
import type { FileWriteHandle } from "../engine/block";

function describe(e: unknown, full: string): Error {
  const code = (e as NodeJS.ErrnoException).code;
  if (code === "EEXIST") return new Error(`${full} exists already: not overwritten`);
  if (code === "EACCES" || code === "EPERM") return new Error(`no permission to write ${full}`);
  if (code === "EISDIR") return new Error(`${full} is a folder, not a file`);
  if (code === "ENOSPC") return new Error(`the disk is full: cannot write ${full}`);
  return new Error(`cannot write ${full}: ${(e as Error).message}`);
}

export function openFileWrite(full: string, opts: { overwrite?: boolean } = {}): FileWriteHandle {
  let fd: number;
  try {
    mkdirSync(dirname(full), { recursive: true });
    fd = openSync(full, opts.overwrite === true ? "w" : "wx");
  } catch (e) {
    throw describe(e, full);
  }
  let open = true;
  let size = 0;
  const guard = (what: () => void) => {
    if (!open) throw new Error(`${full} is closed`);
    try {
      what();
    } catch (e) {
      throw describe(e, full);
    }
  };
  const writeAll = (bytes: Uint8Array, position: number) => {
    let done = 0;
    while (done < bytes.length) {
      done += writeSync(fd, bytes, done, bytes.length - done, position + done);
    }
  };
  return {
    path: full,
    get size() {
      return size;
    },
    write: (bytes) =>
      guard(() => {
        writeAll(bytes, size);
        size += bytes.length;
      }),
    writeAt: (bytes, position) =>
      guard(() => {
        if (position + bytes.length > size) {
          throw new Error(`writeAt ${position}+${bytes.length} is past the end (${size} bytes)`);
        }
        writeAll(bytes, position);
      }),
    sync: () => guard(() => fdatasyncSync(fd)),
    close: () => {
      if (!open) return;
      open = false;
      closeSync(fd);
    },
  };
}
