/**
 * EDF+ and BDF+ as bytes: the header, its fixed-width ASCII fields, the time-stamped annotation
 * lists (TALs) of the "EDF Annotations" signal and the rule that picks the data-record duration.
 *
 * Sources (facts only; no code was taken from any implementation):
 * - EDF: B. Kemp et al., "A simple format for exchange of digitized polygraphic recordings",
 *   Electroencephalogr. Clin. Neurophysiol. 82:391–393 (1992); https://www.edfplus.info/specs/edf.html
 *   (the header layout: 256 bytes, then 256 per signal; ASCII fields left-justified and padded
 *   with spaces; samples are little-endian two's-complement 16-bit integers).
 * - EDF+: B. Kemp & J. Olivan, Clin. Neurophysiol. 114:1755–1761 (2003);
 *   https://www.edfplus.info/specs/edfplus.html ("EDF+C" in the reserved field; the local patient
 *   and recording identification subfields; the "EDF Annotations" signal, whose first TAL in every
 *   data record is empty and gives the record's onset in seconds from the header's start time, the
 *   first record's a fraction of a second; TAL = +onset[\x15duration]\x14text\x14…\x00).
 * - BDF: BioSemi, https://www.biosemi.com/faq/file_format.htm (version byte 255 then "BIOSEMI",
 *   24-bit little-endian samples, digital range −8388608…8388607). BDF+ (T. van Beelen,
 *   https://www.teuniz.net/edfbrowser/bdfplus%20format%20description.html): the header of EDF+
 *   with "BDF+C" in the reserved field and the annotations signal labelled "BDF Annotations".
 */

export type EdfFormat = "edf" | "bdf";

export interface FormatInfo {
  /** Bytes per sample: 2 (EDF) or 3 (BDF). */
  readonly bytes: 2 | 3;
  readonly digitalMin: number;
  readonly digitalMax: number;
  /** The reserved field of a continuous recording. */
  readonly reserved: string;
  readonly annotationLabel: string;
}

export const FORMATS: Readonly<Record<EdfFormat, FormatInfo>> = {
  edf: {
    bytes: 2,
    digitalMin: -32768,
    digitalMax: 32767,
    reserved: "EDF+C",
    annotationLabel: "EDF Annotations",
  },
  bdf: {
    bytes: 3,
    digitalMin: -8388608,
    digitalMax: 8388607,
    reserved: "BDF+C",
    annotationLabel: "BDF Annotations",
  },
};

/** Byte offset of the header's "number of data records" field (8 ASCII characters). */
export const RECORDS_OFFSET = 236;
/** The spec's preference for the size of one data record, bytes (edf.html). */
export const PREFERRED_RECORD_BYTES = 61440;

/** One signal of the header. */
export interface EdfSignalSpec {
  label: string;
  transducer: string;
  dimension: string;
  physicalMin: number;
  physicalMax: number;
  digitalMin: number;
  digitalMax: number;
  prefiltering: string;
  samples: number;
}

export interface EdfHeaderSpec {
  format: EdfFormat;
  /** EDF+ local patient identification: code sex birthdate name ("X" when unknown). */
  patient: string;
  /** Recording start, UNIX seconds; the header keeps its whole second (UTC). */
  start: number;
  /** EDF+ recording identification after "Startdate dd-MMM-yyyy": admin code, technician, equipment. */
  recording: string;
  /** The record duration as written (8 characters at most, exact). */
  recordDuration: string;
  /** -1 while unknown. */
  records: number;
  signals: readonly EdfSignalSpec[];
}

/** Printable ASCII (32–126) only: anything else becomes '_'. */
export function toAscii(text: string): string {
  return text.replace(/[^\x20-\x7e]/g, "_");
}

/** A left-justified, space-padded ASCII field of `width` bytes; throws when the text is longer. */
export function asciiField(text: string, width: number, what: string): string {
  const a = toAscii(text);
  if (a.length > width) {
    throw new Error(`${what} '${a}' is ${a.length} characters; the field holds ${width}`);
  }
  return a.padEnd(width, " ");
}

/**
 * A number in at most `width` characters. Integers and short decimals are written exactly;
 * otherwise the value is rounded to fewer decimals, `toward` says which way ("down" for a
 * physical minimum and "up" for a maximum so the range still covers what was asked).
 */
export function edfNumber(
  x: number,
  width: number,
  toward: "down" | "up" | "nearest" = "nearest",
): string {
  if (!Number.isFinite(x)) throw new Error(`${x} cannot be written in an EDF header`);
  const plain = plainDecimal(x);
  if (plain.length <= width) return plain;
  const intDigits = plainDecimal(Math.trunc(x)).length;
  for (let d = Math.max(0, width - intDigits - 1); d >= 0; d--) {
    const f = 10 ** d;
    const scaled = x * f;
    const r =
      toward === "down"
        ? Math.floor(scaled)
        : toward === "up"
          ? Math.ceil(scaled)
          : Math.round(scaled);
    const s = plainDecimal(r / f);
    if (s.length <= width) return s;
  }
  throw new Error(`${x} does not fit in ${width} characters`);
}

/** A number without exponent, shortest round-trip digits ("0.0005", "-1200"). */
function plainDecimal(x: number): string {
  const s = String(x === 0 ? 0 : x);
  if (!/e/i.test(s)) return s;
  // toFixed gives up to 100 decimals; trim the zeros it adds.
  const f = Math.abs(x) < 1 ? x.toFixed(20) : x.toFixed(0);
  return f.includes(".") ? f.replace(/0+$/, "").replace(/\.$/, "") : f;
}

const MONTHS = [
  "JAN",
  "FEB",
  "MAR",
  "APR",
  "MAY",
  "JUN",
  "JUL",
  "AUG",
  "SEP",
  "OCT",
  "NOV",
  "DEC",
] as const;

const two = (n: number): string => String(n).padStart(2, "0");

/** The header's date (dd.mm.yy), time (hh.mm.ss) and EDF+ Startdate (dd-MMM-yyyy), UTC. */
export function headerDate(start: number): { date: string; time: string; startdate: string } {
  const d = new Date(Math.floor(start) * 1000);
  const y = d.getUTCFullYear();
  return {
    date: `${two(d.getUTCDate())}.${two(d.getUTCMonth() + 1)}.${two(y % 100)}`,
    time: `${two(d.getUTCHours())}.${two(d.getUTCMinutes())}.${two(d.getUTCSeconds())}`,
    startdate: `${two(d.getUTCDate())}-${MONTHS[d.getUTCMonth()]}-${y}`,
  };
}

/** The 8-byte "number of data records" field, for `writeAt(…, RECORDS_OFFSET)`. */
export function recordsField(records: number, into = new Uint8Array(8)): Uint8Array {
  const s = String(records).padEnd(8, " ");
  for (let i = 0; i < 8; i++) into[i] = s.charCodeAt(i);
  return into;
}

/** The whole header: 256 bytes plus 256 per signal. */
export function buildEdfHeader(spec: EdfHeaderSpec): Uint8Array {
  const ns = spec.signals.length;
  const size = 256 * (ns + 1);
  const out = new Uint8Array(size);
  const { date, time, startdate } = headerDate(spec.start);
  let pos = 0;
  const put = (text: string, width: number, what: string) => {
    const f = asciiField(text, width, what);
    for (let i = 0; i < width; i++) out[pos + i] = f.charCodeAt(i);
    pos += width;
  };
  if (spec.format === "bdf") {
    out[0] = 0xff;
    pos = 1;
    put("BIOSEMI", 7, "version");
  } else {
    put("0", 8, "version");
  }
  put(spec.patient, 80, "patient identification");
  put(`Startdate ${startdate} ${spec.recording}`, 80, "recording identification");
  put(date, 8, "start date");
  put(time, 8, "start time");
  put(String(size), 8, "header bytes");
  put(FORMATS[spec.format].reserved, 44, "reserved");
  put(String(spec.records), 8, "number of data records");
  put(spec.recordDuration, 8, "record duration");
  put(String(ns), 4, "number of signals");
  const each = (width: number, what: string, f: (s: EdfSignalSpec) => string) => {
    for (const s of spec.signals) put(f(s), width, `${what} of '${s.label}'`);
  };
  each(16, "label", (s) => s.label);
  each(80, "transducer type", (s) => s.transducer);
  each(8, "physical dimension", (s) => s.dimension);
  each(8, "physical minimum", (s) => edfNumber(s.physicalMin, 8, "down"));
  each(8, "physical maximum", (s) => edfNumber(s.physicalMax, 8, "up"));
  each(8, "digital minimum", (s) => String(s.digitalMin));
  each(8, "digital maximum", (s) => String(s.digitalMax));
  each(80, "prefiltering", (s) => s.prefiltering);
  each(8, "samples per record", (s) => String(s.samples));
  each(32, "reserved", () => "");
  return out;
}

/** "+12.345678": seconds with up to 6 decimals, from whole microseconds (exact). */
export function formatOnset(us: number): string {
  const sign = us < 0 ? "-" : "+";
  const a = Math.abs(Math.round(us));
  const s = Math.floor(a / 1e6);
  const f = a - s * 1e6;
  if (f === 0) return `${sign}${s}`;
  return `${sign}${s}.${String(f).padStart(6, "0").replace(/0+$/, "")}`;
}

/**
 * Writes one TAL at `pos` of `into`: `+onset\x14text\x14\x00` (an empty text gives the
 * time-keeping TAL `+onset\x14\x14\x00`). Returns the position after it, or -1 when it does not fit
 * before `end` (nothing written then).
 */
export function writeTal(
  into: Uint8Array,
  pos: number,
  end: number,
  onsetUs: number,
  text: string,
): number {
  const onset = formatOnset(onsetUs);
  const need = onset.length + text.length + 3;
  if (pos + need > end) return -1;
  let p = pos;
  for (let i = 0; i < onset.length; i++) into[p++] = onset.charCodeAt(i);
  into[p++] = 0x14;
  for (let i = 0; i < text.length; i++) into[p++] = text.charCodeAt(i);
  into[p++] = 0x14;
  into[p++] = 0x00;
  return p;
}

/** Text of an annotation: printable ASCII without the TAL separators (20, 21, 0). */
export function annotationText(text: string, max: number): string {
  const a = toAscii(text);
  return a.length <= max ? a : `${a.slice(0, Math.max(0, max - 3))}...`;
}
