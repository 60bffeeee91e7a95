/**
 * FilePlayer's rows from the lab recordings our recorders write (and other programs': LabRecorder,
 * EDF+/BDF+ viewers): one XDF stream, or EDF+/BDF+ signals of one rate. The file is read whole
 * into memory (at most RECORDING_MAX_BYTES) through the host's `openRead`; each row is one sample
 * with its own time: XDF's timestamps as written (exact, so a recording replays the stamps it
 * was recorded with), EDF's record start (its time-keeping annotation, or record × duration) plus
 * the sample's place in the record. Channel names become the output's labels.
 */
import { BlockConfigError, type FileReadHandle } from "../../engine";
import {
  annotationBytes,
  decodeRecord,
  headerSize,
  parseEdfHeader,
  parseTals,
  type EdfHeader,
} from "../recording/edf-reader";
import { readXdf, type XdfStream } from "../recording/xdf-reader";
import type { RowSource } from "./row-source";

/** The largest recording read (whole, into memory). */
export const RECORDING_MAX_BYTES = 512 * 1024 * 1024;

export type RecordingKind = "xdf" | "edf";

/** "xdf" or "edf" (also .bdf) by the file's extension; undefined for text. */
export function recordingKind(file: string): RecordingKind | undefined {
  const ext = /\.([A-Za-z0-9]+)$/.exec(file)?.[1]?.toLowerCase();
  if (ext === "xdf") return "xdf";
  if (ext === "edf" || ext === "bdf") return "edf";
  return undefined;
}

export interface RecordingOptions {
  file: string;
  /** XDF: the stream's name or 0-based index (default: the first numeric stream). */
  stream?: string | number | undefined;
  /** Channels (XDF) or signals (EDF): labels or 0-based indices, in output order. */
  columns?: readonly (string | number)[] | undefined;
}

/** The rows of a recording, read whole. */
export function recordingRows(
  h: FileReadHandle,
  kind: RecordingKind,
  o: RecordingOptions,
): RowSource {
  if (h.size > RECORDING_MAX_BYTES) {
    throw new BlockConfigError(
      `'${o.file}' has ${h.size} bytes; a FilePlayer reads XDF and EDF recordings whole, at most ` +
        `${RECORDING_MAX_BYTES} (512 MiB): split it, or export the part you need`,
      "File",
    );
  }
  return kind === "xdf" ? xdfRows(h, o) : edfRows(h, o);
}

/** Rows from arrays in memory (times, row-major values). */
function memoryRows(
  t: Float64Array,
  values: Float64Array,
  width: number,
  labels: readonly string[],
  unit: string | undefined,
): RowSource {
  const n = t.length;
  return {
    whole: true,
    width,
    hasTimes: true,
    total: n,
    labels,
    ...(unit ? { unit } : {}),
    fill: (upTo) => Math.min(upTo, n),
    time: (r) => t[r]!,
    line: (r) => r + 1,
    copy(r, into, at) {
      for (let k = 0; k < width; k++) into[at + k] = values[r * width + k]!;
    },
    release() {},
    rewind() {},
    lastTime: () => t[n - 1]!,
    error: undefined,
    close() {},
  };
}

/** Indices of the chosen columns among `names` (labels or 0-based indices), checked. */
function pickColumns(
  names: readonly string[],
  columns: readonly (string | number)[] | undefined,
  what: string,
): number[] {
  if (columns === undefined) return names.map((_, i) => i);
  return columns.map((c) => {
    if (typeof c === "number") {
      if (c < names.length) return c;
      throw new BlockConfigError(
        `Columns: ${what} has ${names.length} channels (0…${names.length - 1}), not ${c}`,
        "Columns",
      );
    }
    const i = names.indexOf(c);
    if (i >= 0) return i;
    throw new BlockConfigError(
      `Columns: ${what} has no channel '${c}' (channels: ${names.slice(0, 20).join(", ")}${names.length > 20 ? ", …" : ""})`,
      "Columns",
    );
  });
}

/** Copies the chosen columns of row-major `values` (width `from`) into a new array. */
function selectColumns(values: Float64Array, from: number, cols: readonly number[]): Float64Array {
  const n = values.length / from;
  const out = new Float64Array(n * cols.length);
  for (let r = 0; r < n; r++) {
    for (let j = 0; j < cols.length; j++) out[r * cols.length + j] = values[r * from + cols[j]!]!;
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// XDF

function pickStream(streams: readonly XdfStream[], o: RecordingOptions): XdfStream {
  const list = streams.map((s, i) => `${i}: ${s.header.name} (${s.header.format})`).join(", ");
  const s =
    o.stream === undefined
      ? streams.find((x) => x.values !== null)
      : typeof o.stream === "number"
        ? streams[o.stream]
        : streams.find((x) => x.header.name === o.stream);
  if (!s) {
    throw new BlockConfigError(
      o.stream === undefined
        ? `'${o.file}' has no numeric stream to play (streams: ${list || "none"})`
        : `'${o.file}' has no stream ${JSON.stringify(o.stream)} (streams: ${list || "none"})`,
      o.stream === undefined ? "File" : "Stream",
    );
  }
  if (s.values === null) {
    throw new BlockConfigError(
      `stream '${s.header.name}' of '${o.file}' holds strings (markers): a FilePlayer plays numbers`,
      "Stream",
    );
  }
  return s;
}

function xdfRows(h: FileReadHandle, o: RecordingOptions): RowSource {
  let x;
  try {
    x = readXdf(h);
  } catch (e) {
    throw new BlockConfigError(
      `'${o.file}' is not a readable XDF file: ${(e as Error).message}`,
      "File",
    );
  }
  const s = pickStream(x.streams, o);
  const width = s.header.channelCount;
  const names = s.header.labels.length === width ? s.header.labels : s.header.labels.map(String);
  const cols = pickColumns(names, o.columns, `stream '${s.header.name}'`);
  const all = cols.length === width && cols.every((c, i) => c === i);
  const values = all ? s.values! : selectColumns(s.values!, width, cols);
  const unit = /<unit>([^<]*)<\/unit>/.exec(s.header.xml)?.[1];
  return memoryRows(
    s.t,
    values,
    cols.length,
    cols.map((c) => names[c]!),
    unit,
  );
}

// ---------------------------------------------------------------------------------------------
// EDF+ / BDF+

function readAll(h: FileReadHandle): Uint8Array {
  const b = new Uint8Array(h.size);
  let got = 0;
  while (got < b.length) {
    const n = h.read(b.subarray(got), got);
    if (n === 0) break;
    got += n;
  }
  return b.subarray(0, got);
}

/** Seconds from the header's start to each record's start (its time-keeping TAL, if any). */
function recordOnsets(hdr: EdfHeader, bytes: Uint8Array, records: number): Float64Array {
  const on = new Float64Array(records);
  const hasTals = hdr.signals.some((s) => s.annotations);
  for (let r = 0; r < records; r++) {
    on[r] = r * hdr.recordDuration;
    if (!hasTals) continue;
    const at = hdr.headerBytes + r * hdr.recordBytes;
    const tals = annotationBytes(hdr, bytes.subarray(at, at + hdr.recordBytes));
    const keep = tals.length > 0 ? parseTals(tals[0]!).find((a) => a.text === "") : undefined;
    if (keep) on[r] = keep.onset;
  }
  return on;
}

function edfRows(h: FileReadHandle, o: RecordingOptions): RowSource {
  const bytes = readAll(h);
  let hdr: EdfHeader;
  try {
    hdr = parseEdfHeader(bytes.subarray(0, headerSize(bytes)));
  } catch (e) {
    throw new BlockConfigError(
      `'${o.file}' is not a readable EDF/BDF file: ${(e as Error).message}`,
      "File",
    );
  }
  const records = Math.floor((bytes.length - hdr.headerBytes) / hdr.recordBytes);
  const signals = hdr.signals.map((s, k) => ({ s, k })).filter((x) => !x.s.annotations);
  const names = signals.map((x) => x.s.label);
  const chosen = pickColumns(names, o.columns, `'${o.file}'`).map((i) => signals[i]!);
  if (chosen.length === 0 || records === 0) {
    throw new BlockConfigError(`'${o.file}' has no data records to play`, "File");
  }
  const perRecord = chosen[0]!.s.samples;
  const odd = chosen.find((x) => x.s.samples !== perRecord);
  if (odd) {
    throw new BlockConfigError(
      `signals '${chosen[0]!.s.label}' (${perRecord} samples per record) and '${odd.s.label}' ` +
        `(${odd.s.samples}) have different rates: choose Columns of one rate`,
      "Columns",
    );
  }
  const width = chosen.length;
  const t = new Float64Array(records * perRecord);
  const values = new Float64Array(records * perRecord * width);
  const onsets = recordOnsets(hdr, bytes, records);
  const out = hdr.signals.map((s) => new Float64Array(s.samples));
  const dt = hdr.recordDuration / perRecord;
  for (let r = 0; r < records; r++) {
    const at = hdr.headerBytes + r * hdr.recordBytes;
    decodeRecord(hdr, bytes.subarray(at, at + hdr.recordBytes), out);
    for (let i = 0; i < perRecord; i++) {
      const row = r * perRecord + i;
      t[row] = hdr.start + onsets[r]! + i * dt;
      for (let j = 0; j < width; j++) values[row * width + j] = out[chosen[j]!.k]![i]!;
    }
  }
  const dims = new Set(chosen.map((x) => x.s.dimension));
  const unit = dims.size === 1 ? [...dims][0] : undefined;
  return memoryRows(
    t,
    values,
    width,
    chosen.map((x) => x.s.label),
    unit,
  );
}
