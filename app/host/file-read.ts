/**
 * `Resources.openRead` for Node (app/engine/block.ts): a file read in pieces, synchronously, so a
 * FilePlayer can play a recording of any size without holding it in memory. What is not a regular
 * file (a device such as /dev/urandom, a pipe) is not opened at all (opening a pipe would wait for
 * a writer): its handle says so with a NaN size.
 */
import { closeSync, openSync, readSync, statSync } from "node:fs";
import type { FileReadHandle } from "../engine/block";

function describe(e: unknown, full: string): Error {
  const code = (e as NodeJS.ErrnoException).code;
  if (code === "ENOENT") return new Error(`file not found: ${full}`);
  if (code === "EACCES") return new Error(`no permission to read ${full}`);
  if (code === "EISDIR") return new Error(`${full} is a folder, not a file`);
  return new Error(`cannot read ${full}: ${(e as Error).message}`);
}

export function openFileRead(full: string): FileReadHandle {
  let size: number;
  try {
    const st = statSync(full);
    if (st.isDirectory()) throw Object.assign(new Error("is a folder"), { code: "EISDIR" });
    size = st.isFile() ? st.size : NaN;
  } catch (e) {
    throw describe(e, full);
  }
  if (Number.isNaN(size)) {
    return {
      path: full,
      size,
      read: () => {
        throw new Error(`${full} is not a regular file`);
      },
      close: () => {},
    };
  }
  let fd: number;
  try {
    fd = openSync(full, "r");
  } catch (e) {
    throw describe(e, full);
  }
  let open = true;
  return {
    path: full,
    size,
    read: (into, position) => {
      try {
        return readSync(fd, into, 0, into.length, position);
      } catch (e) {
        throw describe(e, full);
      }
    },
    close: () => {
      if (!open) return;
      open = false;
      closeSync(fd);
    },
  };
}
