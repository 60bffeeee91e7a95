/**
 * What an EdfRecorder makes of its inputs and params at load: which inputs are signals and which
 * are markers, the labels, dimensions and physical ranges of every signal, the record duration,
 * and the file name. Every refusal is a BlockConfigError naming the param and the input.
 */
import { z } from "zod";
import { BlockConfigError, type BlockContext, type InputInfo } from "../../engine";
import { findInput, inputName, signalInput } from "../shared/inputs";
import { MAX_CHANNELS, MAX_ITEMS } from "../shared/limits";
import { chooseRecordDuration, type RecordDuration } from "./edf-duration";
import { FORMATS, toAscii, type EdfFormat } from "./edf-writer";
import type { EdfStreamInput } from "./edf-stream";

const range = z
  .tuple([z.number(), z.number()])
  .refine(([a, b]) => a < b, { message: "a physical range is [min, max] with min < max" });

export const edfParams = z.strictObject({
  File: z
    .string()
    .min(1)
    .default("recordings/{block}-{date}-{time}")
    .describe(
      "The file, relative to the pipeline file; {block}, {date} (YYYYMMDD) and {time} (HHMMSS, UTC, " +
        "when the recording starts) are replaced, .edf or .bdf is added when missing, and an " +
        "existing file is never overwritten: -2, -3, … is added to the name",
    ),
  Format: z
    .enum(["edf", "bdf"])
    .optional()
    .describe(
      "edf: EDF+ with 16-bit samples; bdf: BDF+ with 24-bit samples. Default: from the File's " +
        "extension, else edf",
    ),
  Recording: z
    .boolean()
    .default(true)
    .describe(
      "Record; false finishes the file and true starts a new one (can be changed while running)",
    ),
  PhysicalRange: z
    .union([range, z.array(range).min(1).max(MAX_CHANNELS)])
    .optional()
    .describe(
      "[min, max] in Dimension units for every signal, or one [min, max] per signal channel in " +
        "input order; values outside are written as min or max and counted as clipped. Default: " +
        "per input, ±10 × the largest absolute value of its first data record, rounded up to " +
        "1, 2 or 5 × 10^k (±1 when that record is all zeros)",
    ),
  Dimension: z
    .union([z.string().max(8), z.array(z.string().max(8)).min(1).max(MAX_CHANNELS)])
    .optional()
    .describe(
      "Physical dimension (8 ASCII characters at most): one for all, or one per channel. " +
        "Default: the unit the input's block gives its channels, else uV",
    ),
  Labels: z
    .array(z.string().min(1).max(16))
    .max(MAX_CHANNELS)
    .optional()
    .describe(
      "One label per signal channel, in input order (16 ASCII characters at most). Default: the " +
        "channel names the input's block gives, else the input's name and the channel number ('Emg 3')",
    ),
  RecordDuration: z
    .number()
    .positive()
    .max(60)
    .optional()
    .describe(
      "Seconds per data record; every signal input's rate must give a whole number of samples. " +
        "Default: the longest multiple of the shortest such duration that is at most 0.5 s and " +
        "keeps a record within 61 440 bytes",
    ),
  Markers: z
    .array(z.string().min(1))
    .max(MAX_ITEMS)
    .optional()
    .describe(
      "Inputs written as annotations rather than signals. Default: aperiodic inputs (a " +
        "Trigger's) and the event outputs of Stimulus (phase, cue, trigger), StimTrigger and TAC",
    ),
  Patient: z
    .string()
    .max(80)
    .default("X X X X")
    .describe(
      "EDF+ patient identification: code, sex (F/M), birthdate (dd-MMM-yyyy) and name, " +
        "separated by spaces, X for unknown, spaces inside a subfield written as _",
    ),
});

export type EdfParams = z.output<typeof edfParams>;

/** A signal input: its position in Inputs and samples per event (rows of a matrix value). */
export interface SignalSlot {
  index: number;
  rows: number;
  channels: number;
}

/** A marker input: annotations from its events (on every event, or when the value changes). */
export interface MarkerSlot {
  index: number;
  source: string;
  onChange: boolean;
}

export interface EdfSetup {
  format: EdfFormat;
  signals: SignalSlot[];
  markers: MarkerSlot[];
  /** Stream inputs, in the order of `signals`. */
  streamInputs: EdfStreamInput[];
  duration: RecordDuration;
  annotationBytes: number;
}

/** Bytes for the time-keeping TAL, and for markers when there are marker inputs. */
const KEEPING_BYTES = 36;
const MARKER_BYTES = 180;
/** Longest annotation text written (longer ones end in ...). */
export const MAX_MARKER_TEXT = MARKER_BYTES - 24;

const EVENT_PORTS: Record<string, readonly string[] | "all"> = {
  Stimulus: ["phase", "cue", "trigger"],
  StimTrigger: "all",
  TAC: "all",
  Trigger: "all",
};

function isDefaultMarker(i: InputInfo): boolean {
  if (i.rate === 0) return true;
  const ports = i.type === undefined ? undefined : EVENT_PORTS[i.type];
  return ports === "all" || (ports !== undefined && ports.includes(i.port));
}

export function formatOf(p: EdfParams): EdfFormat {
  if (p.Format !== undefined) {
    const ext = /\.(edf|bdf)$/i.exec(p.File)?.[1]?.toLowerCase();
    if (ext !== undefined && ext !== p.Format) {
      throw new BlockConfigError(
        `File ends in .${ext} but Format is ${p.Format}: make them agree (or leave the extension out)`,
        "File",
      );
    }
    return p.Format;
  }
  return /\.bdf$/i.test(p.File) ? "bdf" : "edf";
}

function markerSlots(ctx: BlockContext, p: EdfParams): MarkerSlot[] {
  const chosen = p.Markers?.map((m) => findInput(ctx, m, "Markers").index);
  return ctx.inputs
    .filter((i) => (chosen ? chosen.includes(i.index) : isDefaultMarker(i)))
    .map((i) => {
      if (i.isTimer) {
        throw new BlockConfigError(
          `input ${inputName(i)} is a timer (its events carry no values): connect the block it drives`,
        );
      }
      return { index: i.index, source: i.source, onChange: i.rate > 0 };
    });
}

function signalSlots(ctx: BlockContext, markers: readonly MarkerSlot[]): SignalSlot[] {
  const slots = ctx.inputs
    .filter((i) => !markers.some((m) => m.index === i.index))
    .map((i) => {
      const s = signalInput(ctx, i.index);
      return { index: i.index, rows: s.shape.rows, channels: s.shape.cols };
    });
  if (slots.length === 0) {
    throw new BlockConfigError(
      "EdfRecorder needs at least one periodic signal input: its inputs are all markers " +
        "(aperiodic, or listed in Markers), and an EDF file's data records need signals",
    );
  }
  return slots;
}

/** The source's name for channel `c` of `channels` (its first row's, for a matrix). */
function metaLabel(i: InputInfo, c: number, channels: number): string | undefined {
  const labels = i.meta?.labels;
  if (labels === undefined || labels.length < channels) return undefined;
  return labels[c];
}

/**
 * The sources' own channel names (port meta) of every signal, or undefined per channel without
 * one; an input sharing a name with another ("EMG 1" of two simulators) has all its names
 * qualified by its source's name ("Trigno EMG 1").
 */
function ownLabels(ctx: BlockContext, signals: readonly SignalSlot[]): (string | undefined)[][] {
  const own = signals.map((s) => {
    const info = ctx.inputs[s.index]!;
    return Array.from({ length: s.channels }, (_, c) => metaLabel(info, c, s.channels));
  });
  const inputsWith = new Map<string, number>();
  for (const labels of own) {
    for (const l of new Set(labels)) {
      if (l !== undefined) inputsWith.set(l, (inputsWith.get(l) ?? 0) + 1);
    }
  }
  return own.map((labels, i) => {
    if (!labels.some((l) => l !== undefined && inputsWith.get(l)! > 1)) return labels;
    const source = ctx.inputs[signals[i]!.index]!.source;
    return labels.map((l) => (l === undefined ? l : `${source} ${l}`));
  });
}

/** Labels of every signal channel: Labels, the source's names, or 'Input k'; unique, 16 characters. */
function channelLabels(ctx: BlockContext, p: EdfParams, signals: readonly SignalSlot[]): string[] {
  const total = signals.reduce((a, s) => a + s.channels, 0);
  if (p.Labels) {
    if (p.Labels.length !== total) {
      throw new BlockConfigError(
        `Labels has ${p.Labels.length} names but the signal inputs have ${total} channels`,
        "Labels",
      );
    }
    return p.Labels.map(toAscii);
  }
  const own = ownLabels(ctx, signals);
  const seen = new Set<string>();
  const out: string[] = [];
  signals.forEach((s, i) => {
    const name = toAscii(ctx.inputs[s.index]!.source);
    for (let c = 0; c < s.channels; c++) {
      const mine = own[i]![c];
      const suffix = mine !== undefined || s.channels === 1 ? "" : ` ${c + 1}`;
      const base = mine !== undefined ? toAscii(mine) : name;
      let label = base.slice(0, 16 - suffix.length) + suffix;
      for (let k = 2; seen.has(label); k++) label = `${base.slice(0, 12)}~${k}${suffix}`.slice(-16);
      seen.add(label);
      out.push(label);
    }
  });
  return out;
}

function perChannel<T>(value: T | T[], total: number, param: string, what: string): T[] | null {
  if (!Array.isArray(value)) return null;
  if (value.length !== total) {
    throw new BlockConfigError(
      `${param} has ${value.length} ${what} but the signal inputs have ${total} channels: give one ` +
        `for all or one per channel`,
      param,
    );
  }
  return value;
}

function streamInputs(
  ctx: BlockContext,
  p: EdfParams,
  signals: readonly SignalSlot[],
  duration: RecordDuration,
): EdfStreamInput[] {
  const total = signals.reduce((a, s) => a + s.channels, 0);
  const labels = channelLabels(ctx, p, signals);
  const dims =
    p.Dimension === undefined ? null : perChannel(p.Dimension, total, "Dimension", "dimensions");
  const pr = p.PhysicalRange;
  const ranges =
    pr === undefined
      ? null
      : typeof pr[0] === "number"
        ? Array.from({ length: total }, () => pr as [number, number])
        : perChannel(pr as [number, number][], total, "PhysicalRange", "ranges")!;
  let at = 0;
  return signals.map((s, k) => {
    const from = at;
    at += s.channels;
    return {
      channels: s.channels,
      samplesPerRecord: duration.samples[k]!,
      labels: labels.slice(from, at),
      dimensions: dims
        ? dims.slice(from, at).map(toAscii)
        : Array<string>(s.channels).fill(dimensionOf(ctx.inputs[s.index]!, p.Dimension)),
      ranges: ranges ? ranges.slice(from, at) : null,
    };
  });
}

/** One Dimension for all, else the source's unit (8 characters), else uV. */
function dimensionOf(i: InputInfo, given: EdfParams["Dimension"]): string {
  if (typeof given === "string") return toAscii(given);
  const unit = i.meta?.unit;
  return unit !== undefined && toAscii(unit).length <= 8 ? toAscii(unit) : "uV";
}

export function resolveEdfSetup(ctx: BlockContext, p: EdfParams): EdfSetup {
  const format = formatOf(p);
  const markers = markerSlots(ctx, p);
  const signals = signalSlots(ctx, markers);
  const bps = FORMATS[format].bytes;
  const want = KEEPING_BYTES + (markers.length > 0 ? MARKER_BYTES : 0);
  const annotationBytes = Math.ceil(want / bps) * bps;
  let duration: RecordDuration;
  try {
    duration = chooseRecordDuration(
      signals.map((s) => {
        const i = ctx.inputs[s.index]!;
        if (!(i.rate > 0)) {
          throw new Error(`input ${inputName(i)} has no known rate: give it a DesiredRate`);
        }
        return { rate: i.rate * s.rows, bytesPerSample: s.channels * bps, name: inputName(i) };
      }),
      { annotationBytes, ...(p.RecordDuration === undefined ? {} : { fixed: p.RecordDuration }) },
    );
  } catch (e) {
    throw new BlockConfigError((e as Error).message, "RecordDuration");
  }
  return {
    format,
    signals,
    markers,
    streamInputs: streamInputs(ctx, p, signals, duration),
    duration,
    annotationBytes,
  };
}

const pad2 = (n: number): string => String(n).padStart(2, "0");

/** The File pattern with {block}, {date}, {time} (UTC at `t`) and the extension; suffix n ≥ 2: -n. */
export function edfFileName(
  pattern: string,
  block: string,
  t: number,
  format: EdfFormat,
  n = 1,
): string {
  const d = new Date(Math.floor(t) * 1000);
  const date = `${d.getUTCFullYear()}${pad2(d.getUTCMonth() + 1)}${pad2(d.getUTCDate())}`;
  const time = `${pad2(d.getUTCHours())}${pad2(d.getUTCMinutes())}${pad2(d.getUTCSeconds())}`;
  const name = pattern
    .replaceAll("{block}", block)
    .replaceAll("{date}", date)
    .replaceAll("{time}", time);
  const m = /\.(edf|bdf)$/i.exec(name);
  const stem = m ? name.slice(0, -m[0].length) : name;
  const ext = m ? m[0] : `.${format}`;
  return n <= 1 ? `${stem}${ext}` : `${stem}-${n}${ext}`;
}
