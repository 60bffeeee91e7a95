/**
 * Reads EDF/EDF+ and BDF/BDF+ files (specs cited in edf-writer.ts): the header, data records as
 * physical values, and the TALs of the annotations signal. Pure functions over bytes, so that a
 * FilePlayer can read a file in pieces through `Resources.openRead` and `mosaic repair` can check
 * one; errors name the field and say what was expected.
 */
import type { EdfFormat } from "./edf-writer";

export interface EdfSignalHeader {
  label: string;
  transducer: string;
  dimension: string;
  physicalMin: number;
  physicalMax: number;
  digitalMin: number;
  digitalMax: number;
  prefiltering: string;
  samples: number;
  /** True for the "EDF Annotations" / "BDF Annotations" signal. */
  annotations: boolean;
}

export interface EdfHeader {
  format: EdfFormat;
  patient: string;
  recording: string;
  /** dd.mm.yy and hh.mm.ss as written. */
  startDate: string;
  startTime: string;
  /** UNIX seconds of the header's start date and time, read as UTC (1985–2084). */
  start: number;
  headerBytes: number;
  reserved: string;
  /** -1 when unknown. */
  records: number;
  recordDuration: number;
  signals: EdfSignalHeader[];
  /** Bytes of one data record. */
  recordBytes: number;
  bytesPerSample: 2 | 3;
}

export interface EdfAnnotation {
  /** Seconds from the header's start time. */
  onset: number;
  duration: number | null;
  text: string;
}

const ascii = (b: Uint8Array, from: number, width: number): string => {
  let s = "";
  for (let i = from; i < from + width; i++) s += String.fromCharCode(b[i]!);
  return s.trimEnd();
};

function num(b: Uint8Array, from: number, width: number, what: string): number {
  const s = ascii(b, from, width).trim();
  const x = Number(s);
  if (s === "" || !Number.isFinite(x)) {
    throw new Error(
      `the header's ${what} (bytes ${from}–${from + width - 1}) is '${s}', not a number`,
    );
  }
  return x;
}

/** How many bytes of the file the header takes, from its first 256 bytes. */
export function headerSize(first: Uint8Array): number {
  if (first.length < 256) throw new Error(`${first.length} bytes: an EDF header has at least 256`);
  const ns = num(first, 252, 4, "number of signals");
  return 256 * (ns + 1);
}

/** Parses the header (all of it: `headerSize` bytes). */
export function parseEdfHeader(b: Uint8Array): EdfHeader {
  const format = detectFormat(b);
  const headerBytes = num(b, 184, 8, "number of header bytes");
  const ns = num(b, 252, 4, "number of signals");
  if (!Number.isInteger(ns) || ns < 1) throw new Error(`the header says ${ns} signals`);
  if (headerBytes !== 256 * (ns + 1)) {
    throw new Error(
      `the header says ${headerBytes} bytes, but ${ns} signals need ${256 * (ns + 1)}`,
    );
  }
  if (b.length < headerBytes)
    throw new Error(`the header needs ${headerBytes} bytes, got ${b.length}`);
  const bytesPerSample = format === "bdf" ? 3 : 2;
  const signals = readSignals(b, ns, format);
  const recordBytes = signals.reduce((a, s) => a + s.samples * bytesPerSample, 0);
  const startDate = ascii(b, 168, 8);
  const startTime = ascii(b, 176, 8);
  return {
    format,
    patient: ascii(b, 8, 80),
    recording: ascii(b, 88, 80),
    startDate,
    startTime,
    start: parseStart(startDate, startTime),
    headerBytes,
    reserved: ascii(b, 192, 44),
    records: num(b, 236, 8, "number of data records"),
    recordDuration: num(b, 244, 8, "record duration"),
    signals,
    recordBytes,
    bytesPerSample,
  };
}

function detectFormat(b: Uint8Array): EdfFormat {
  if (b[0] === 0xff && ascii(b, 1, 7) === "BIOSEMI") return "bdf";
  if (ascii(b, 0, 8) === "0") return "edf";
  throw new Error(
    `the version field is '${ascii(b, 0, 8)}': neither EDF ("0") nor BDF (255 BIOSEMI)`,
  );
}

function readSignals(b: Uint8Array, ns: number, format: EdfFormat): EdfSignalHeader[] {
  let at = 256;
  const field = (width: number) => {
    const from = at;
    at += width * ns;
    return (k: number) => from + k * width;
  };
  const label = field(16);
  const transducer = field(80);
  const dimension = field(8);
  const pmin = field(8);
  const pmax = field(8);
  const dmin = field(8);
  const dmax = field(8);
  const prefilter = field(80);
  const samples = field(8);
  const annotationLabel = format === "bdf" ? "BDF Annotations" : "EDF Annotations";
  return Array.from({ length: ns }, (_, k) => {
    const l = ascii(b, label(k), 16);
    return {
      label: l,
      transducer: ascii(b, transducer(k), 80),
      dimension: ascii(b, dimension(k), 8),
      physicalMin: num(b, pmin(k), 8, `physical minimum of signal ${k + 1}`),
      physicalMax: num(b, pmax(k), 8, `physical maximum of signal ${k + 1}`),
      digitalMin: num(b, dmin(k), 8, `digital minimum of signal ${k + 1}`),
      digitalMax: num(b, dmax(k), 8, `digital maximum of signal ${k + 1}`),
      prefiltering: ascii(b, prefilter(k), 80),
      samples: num(b, samples(k), 8, `samples per record of signal ${k + 1}`),
      annotations: l === annotationLabel || l === "EDF Annotations",
    };
  });
}

function parseStart(date: string, time: string): number {
  const d = /^(\d\d)\.(\d\d)\.(\d\d)$/.exec(date);
  const t = /^(\d\d)\.(\d\d)\.(\d\d)$/.exec(time);
  if (!d || !t) return NaN;
  const yy = Number(d[3]);
  const year = yy >= 85 ? 1900 + yy : 2000 + yy;
  return (
    Date.UTC(year, Number(d[2]) - 1, Number(d[1]), Number(t[1]), Number(t[2]), Number(t[3])) / 1000
  );
}

/**
 * Decodes data record bytes into physical values: `out[k]` receives signal k's samples (its
 * `samples` values) at `offset`. Annotation signals are skipped (read them with `parseTals`).
 */
export function decodeRecord(
  h: EdfHeader,
  record: Uint8Array,
  out: Float64Array[],
  offset = 0,
): void {
  let at = 0;
  h.signals.forEach((s, k) => {
    const n = s.samples;
    if (s.annotations) {
      at += n * h.bytesPerSample;
      return;
    }
    const g = (s.physicalMax - s.physicalMin) / (s.digitalMax - s.digitalMin);
    const o = out[k]!;
    for (let i = 0; i < n; i++) {
      const d = h.bytesPerSample === 3 ? int24(record, at) : int16(record, at);
      at += h.bytesPerSample;
      o[offset + i] = s.physicalMin + (d - s.digitalMin) * g;
    }
  });
}

/** The digital value (an integer) of signal `k`'s sample `i` in a record. */
export function digitalSample(h: EdfHeader, record: Uint8Array, k: number, i: number): number {
  let at = 0;
  for (let j = 0; j < k; j++) at += h.signals[j]!.samples * h.bytesPerSample;
  at += i * h.bytesPerSample;
  return h.bytesPerSample === 3 ? int24(record, at) : int16(record, at);
}

const int16 = (b: Uint8Array, at: number): number => ((b[at]! | (b[at + 1]! << 8)) << 16) >> 16;
const int24 = (b: Uint8Array, at: number): number =>
  ((b[at]! | (b[at + 1]! << 8) | (b[at + 2]! << 16)) << 8) >> 8;

/** The bytes of the annotations signal(s) of one record. */
export function annotationBytes(h: EdfHeader, record: Uint8Array): Uint8Array[] {
  const out: Uint8Array[] = [];
  let at = 0;
  for (const s of h.signals) {
    const len = s.samples * h.bytesPerSample;
    if (s.annotations) out.push(record.subarray(at, at + len));
    at += len;
  }
  return out;
}

/**
 * The TALs of an annotations signal's bytes: `+onset[\x15duration]\x14text\x14…\x00`, zero bytes
 * between and after. An empty text (the time-keeping TAL) is returned with text "".
 */
export function parseTals(bytes: Uint8Array): EdfAnnotation[] {
  const out: EdfAnnotation[] = [];
  let i = 0;
  while (i < bytes.length) {
    if (bytes[i] === 0) {
      i++;
      continue;
    }
    let end = i;
    while (end < bytes.length && bytes[end] !== 0) end++;
    out.push(...parseTal(ascii(bytes, i, end - i)));
    i = end + 1;
  }
  return out;
}

function parseTal(tal: string): EdfAnnotation[] {
  const parts = tal.split("\x14");
  const head = parts[0]!;
  const [on, dur] = head.split("\x15");
  const onset = Number(on);
  if (!/^[+-]\d+(\.\d*)?$/.test(on ?? "") || !Number.isFinite(onset)) {
    throw new Error(`'${head}' is not a TAL onset (+seconds or -seconds)`);
  }
  const duration = dur === undefined || dur === "" ? null : Number(dur);
  const texts = parts.slice(1, parts.length - 1);
  if (texts.length === 0 || texts.every((t) => t === "")) return [{ onset, duration, text: "" }];
  return texts.filter((t) => t !== "").map((text) => ({ onset, duration, text }));
}
