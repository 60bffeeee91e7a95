/**
 * FilePlayer: reading and choosing a recording's rows. A delimited text read whole or streamed as
 * it plays (bigger than FILE_LIMITS.wholeBytes, Node hosts), or an XDF / EDF+ recording
 * (recording-rows.ts); each a RowSource.
 */
import { BlockConfigError, errorMessage, type FileReadHandle, type Resources } from "../../engine";
import {
  DelimitedStream,
  FILE_LIMITS,
  lastRowTime,
  parseDelimited,
  type ParseOptions,
} from "./delimited-text";
import { recordingKind, recordingRows } from "./recording-rows";
import type { RowSource } from "./row-source";

/** The FilePlayer's params (after validation). */
export interface FilePlayerParams {
  File: string;
  Columns?: (string | number)[] | undefined;
  Stream?: string | number | undefined;
  TimeColumn?: string | number | false | undefined;
  Header: "auto" | boolean;
  Delimiter: "auto" | "," | ";" | "\t" | " ";
  Loop: boolean;
  Speed: number;
}

/** The message for a row whose time is before the previous row's. */
export const disorderText = (line: number, file: string, t: number, prev: number): string =>
  `line ${line} of '${file}': time ${t} is before the previous row's ${prev}; original ` +
  "timing needs non-decreasing times";

function wholeRows(text: string, o: ParseOptions): RowSource {
  const t = parseDelimited(text, o);
  const c = t.columns.length;
  return {
    whole: true,
    width: c,
    ...(t.hasHeader ? { labels: t.columns.map((k) => t.names[k]!) } : {}),
    hasTimes: t.times !== null,
    total: t.rows,
    fill: (upTo) => Math.min(upTo, t.rows),
    time: (r) => t.times![r]!,
    line: (r) => t.lines[r]!,
    copy(r, into, at) {
      for (let k = 0; k < c; k++) into[at + k] = t.values[r * c + k]!;
    },
    release() {},
    rewind() {},
    lastTime: () => t.times![t.rows - 1]!,
    error: undefined,
    close() {},
  };
}

/**
 * A big file's rows, read as they play. With `ordered` (original timing), a row whose time is
 * before the previous one ends the rows there.
 */
function streamedRows(h: FileReadHandle, o: ParseOptions, ordered: boolean): RowSource {
  const s = new DelimitedStream(h, o);
  let checked = 0;
  let prev = -Infinity;
  let disorder: string | undefined;
  let total: number | undefined;
  return {
    whole: false,
    width: s.layout.columns.length,
    hasTimes: s.layout.timeColumn >= 0,
    get total() {
      return total;
    },
    fill(upTo) {
      let n = s.fill(upTo);
      if (ordered) {
        for (; checked < n && disorder === undefined; checked++) {
          const t = s.time(checked);
          if (!(t >= prev)) {
            disorder = disorderText(s.line(checked), o.file, t, prev);
            break;
          }
          prev = t;
        }
        if (disorder !== undefined) n = Math.min(n, checked);
      }
      if (s.ended && s.error === undefined && disorder === undefined) total = s.known;
      return n;
    },
    time: (r) => s.time(r),
    line: (r) => s.line(r),
    copy: (r, into, at) => s.copy(r, into, at),
    release: (r) => s.release(r),
    rewind() {
      s.rewind();
      checked = 0;
      prev = -Infinity;
    },
    lastTime: () => lastRowTime(h, h.size, s.layout, o),
    get error() {
      return disorder ?? s.error?.message;
    },
    close: () => h.close(),
  };
}

/** Reads a whole (small) file through its handle. */
function readWhole(h: FileReadHandle): string {
  const buf = new Uint8Array(h.size);
  let got = 0;
  while (got < buf.length) {
    const n = h.read(buf.subarray(got), got);
    if (n === 0) break;
    got += n;
  }
  const decoder = new (
    globalThis as unknown as {
      TextDecoder: new () => { decode(b: Uint8Array): string };
    }
  ).TextDecoder();
  return decoder.decode(buf.subarray(0, got));
}

/**
 * Opens the recording: streamed when the host reads in pieces (Node) and the file is bigger than
 * FILE_LIMITS.wholeBytes, else read whole (and a text bigger than that refused). With `ordered`
 * (original timing), a streamed file's rows end at a row whose time goes back.
 */
export async function loadRows(
  res: Resources,
  p: FilePlayerParams,
  ordered: boolean,
): Promise<RowSource> {
  const o: ParseOptions = {
    file: p.File,
    header: p.Header,
    delimiter: p.Delimiter,
    columns: p.Columns,
    timeColumn: p.TimeColumn,
  };
  const h = openHandle(res, p.File);
  const kind = recordingKind(p.File);
  if (kind) return openRecording(h, kind, p);
  if (h && h.size > FILE_LIMITS.wholeBytes) {
    try {
      return streamedRows(h, o, ordered);
    } catch (e) {
      h.close();
      throw e;
    }
  }
  return wholeRows(await readText(res, p.File, h), o);
}

/** Where `file` is, for messages (the name as given when it cannot be resolved). */
function where(res: Resources, file: string): string {
  try {
    return res.resolve(file);
  } catch {
    return file;
  }
}

/** A handle to read `file` in pieces, where the host gives one; refuses what is not a file. */
function openHandle(res: Resources, file: string): FileReadHandle | undefined {
  let h: FileReadHandle | undefined;
  try {
    h = res.openRead?.(file);
  } catch (e) {
    throw new BlockConfigError(`cannot read '${where(res, file)}': ${errorMessage(e)}`, "File");
  }
  if (h && Number.isNaN(h.size)) {
    throw new BlockConfigError(
      `'${h.path}' is not a regular file (a device or a pipe): a FilePlayer plays recordings ` +
        "saved as files",
      "File",
    );
  }
  return h;
}

/** The whole text of `file` (through `h` when there is one, which it closes), at most FILE_LIMITS.wholeBytes. */
async function readText(
  res: Resources,
  file: string,
  h: FileReadHandle | undefined,
): Promise<string> {
  let text: string;
  try {
    text = h ? readWhole(h) : await res.readText(file);
  } catch (e) {
    throw new BlockConfigError(`cannot read '${where(res, file)}': ${errorMessage(e)}`, "File");
  } finally {
    h?.close();
  }
  if (text.length > FILE_LIMITS.wholeBytes) {
    throw new BlockConfigError(
      `'${file}' has ${text.length} characters; here a recording is read whole, at most ` +
        `${FILE_LIMITS.wholeBytes} (mosaic run and the desktop app play bigger files as they read ` +
        "them)",
      "File",
    );
  }
  return text;
}

/** An XDF or EDF+/BDF+ recording, read whole (Node hosts; a browser cannot read them yet). */
function openRecording(
  h: FileReadHandle | undefined,
  kind: "xdf" | "edf",
  p: FilePlayerParams,
): RowSource {
  if (!h) {
    throw new BlockConfigError(
      `'${p.File}' is ${kind === "xdf" ? "an XDF" : "an EDF+/BDF+"} recording: this runtime cannot read binary files (play it with mosaic run, mosaic serve or the desktop app)`,
      "File",
    );
  }
  try {
    return recordingRows(h, kind, {
      file: p.File,
      stream: p.Stream,
      columns: p.Columns,
    });
  } finally {
    h.close();
  }
}
