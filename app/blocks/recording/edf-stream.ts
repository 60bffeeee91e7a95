/**
 * Streams samples into EDF+/BDF+ data records (edf-writer.ts has the format). Each input is a
 * group of signals with its own samples per record; samples wait in one Float64Array queue per
 * input and a record is written as soon as every input holds enough for it, so a killed recording
 * loses at most the record being filled. The header's record count is rewritten after every
 * batch of records (`writeAt`), so the file opens whatever moment the process dies.
 *
 * The header goes out with the first record: the start time is the earliest first sample, and
 * an automatic physical range is taken from that record's data. An input that falls more than
 * `maxLagRecords` behind another is padded (its last value held) so that the others keep being
 * written; as many of its late samples are then dropped to stay aligned. Both are counted.
 */
import {
  buildEdfHeader,
  edfNumber,
  FORMATS,
  recordsField,
  RECORDS_OFFSET,
  writeTal,
  type EdfFormat,
  type EdfSignalSpec,
} from "./edf-writer";

/** Where the bytes go (a `FileWriteHandle`). */
export interface EdfSink {
  write(bytes: Uint8Array): void;
  writeAt(bytes: Uint8Array, position: number): void;
  readonly size: number;
}

/** One input: `channels` signals sampled together. */
export interface EdfStreamInput {
  channels: number;
  samplesPerRecord: number;
  labels: readonly string[];
  dimensions: readonly string[];
  /** Per channel [min, max]; null: chosen from the first record (autoRange). */
  ranges: readonly (readonly [number, number])[] | null;
}

export interface EdfStreamOptions {
  format: EdfFormat;
  inputs: readonly EdfStreamInput[];
  recordUs: number;
  recordText: string;
  /** Bytes of the annotations signal per record (a multiple of the sample size). */
  annotationBytes: number;
  patient: string;
  recording: string;
  /** Records an input may run ahead of another before the other is padded. */
  maxLagRecords: number;
}

export interface EdfCounts {
  records: number;
  /** Values outside the physical range, written as its end. */
  clipped: number;
  /** NaN values, written as the digital minimum. */
  nan: number;
  /** Samples (per input, all channels together) held to keep inputs aligned, and dropped later. */
  padded: number;
  dropped: number;
  /** Annotations written, and refused (queue full). */
  annotations: number;
  annotationsLost: number;
}

const MAX_QUEUED_ANNOTATIONS = 10_000;

/** ±(10 × the largest |value|) rounded up to 1, 2 or 5 × 10^k; ±1 when all are zero or NaN. */
export function autoRange(values: Float64Array, from: number, to: number): [number, number] {
  let m = 0;
  for (let k = from; k < to; k++) {
    const a = Math.abs(values[k]!);
    if (a > m) m = a;
  }
  if (!(m > 0) || !Number.isFinite(m)) return [-1, 1];
  const x = 10 * m;
  const e = 10 ** Math.floor(Math.log10(x));
  const step = [1, 2, 5, 10].find((s) => s * e >= x * (1 - 1e-12))! * e;
  const r = Number(step.toPrecision(12));
  return [-r, r];
}

class InputQueue {
  values: Float64Array;
  head = 0; // first queued sample
  count = 0;
  debt = 0; // samples to drop (padded earlier)
  first = NaN; // time of the first sample
  readonly last: Float64Array;
  constructor(
    readonly channels: number,
    capacity: number,
  ) {
    this.values = new Float64Array(capacity * channels);
    this.last = new Float64Array(channels);
  }
  get capacity(): number {
    return this.values.length / this.channels;
  }
  free(): number {
    if (this.head > 0 && this.head + this.count === this.capacity) this.compact();
    return this.capacity - this.head - this.count;
  }
  compact(): void {
    const c = this.channels;
    this.values.copyWithin(0, this.head * c, (this.head + this.count) * c);
    this.head = 0;
  }
  push(v: Float64Array, from: number, samples: number): void {
    const c = this.channels;
    const at = (this.head + this.count) * c;
    this.values.set(v.subarray(from * c, (from + samples) * c), at);
    this.count += samples;
    this.last.set(v.subarray((from + samples - 1) * c, (from + samples) * c));
  }
  /** Holds the last value for `samples` samples (room is there). */
  pad(samples: number): void {
    const c = this.channels;
    let at = (this.head + this.count) * c;
    for (let s = 0; s < samples; s++, at += c) this.values.set(this.last, at);
    this.count += samples;
  }
  take(samples: number): void {
    this.head += samples;
    this.count -= samples;
    if (this.count === 0) this.head = 0;
  }
}

export class EdfStream {
  readonly counts: EdfCounts = {
    records: 0,
    clipped: 0,
    nan: 0,
    padded: 0,
    dropped: 0,
    annotations: 0,
    annotationsLost: 0,
  };
  /** The file's start (UNIX seconds): set when the header is written. */
  start = NaN;
  private readonly queues: InputQueue[];
  private readonly record: Uint8Array;
  private readonly countField = new Uint8Array(8);
  private readonly annotationOffset: number;
  private readonly pending: { t: number; text: string }[] = [];
  /** Per input and channel: physical min, gain (digital per physical unit). */
  private lo: Float64Array[] = [];
  private gain: Float64Array[] = [];
  private headerWritten = false;
  private startWhole = 0; // whole seconds of the start
  private startFracUs = 0;

  constructor(
    private readonly opts: EdfStreamOptions,
    private readonly sink: EdfSink,
  ) {
    const bps = FORMATS[opts.format].bytes;
    let bytes = 0;
    this.queues = opts.inputs.map((i) => {
      bytes += i.channels * i.samplesPerRecord * bps;
      return new InputQueue(i.channels, i.samplesPerRecord * (opts.maxLagRecords + 1));
    });
    this.annotationOffset = bytes;
    this.record = new Uint8Array(bytes + opts.annotationBytes);
  }

  /** Bytes of one data record. */
  get recordBytes(): number {
    return this.record.length;
  }

  /** Appends `samples` samples of input `k` (`v` sample-major, `channels` values each). */
  append(k: number, t0: number, v: Float64Array, samples: number): void {
    const q = this.queues[k]!;
    if (Number.isNaN(q.first)) q.first = t0;
    let from = 0;
    if (q.debt > 0) {
      const d = Math.min(q.debt, samples);
      q.debt -= d;
      this.counts.dropped += d;
      from = d;
    }
    let written = 0;
    while (from < samples) {
      let room = q.free();
      if (room === 0) {
        written += this.flush(true);
        room = q.free();
      }
      const m = Math.min(room, samples - from);
      q.push(v, from, m);
      from += m;
    }
    written += this.flush(false);
    if (written > 0) this.updateCount();
  }

  /** Queues an annotation at time `t` (UNIX seconds); written with the next record that has room. */
  annotate(t: number, text: string): void {
    if (this.pending.length >= MAX_QUEUED_ANNOTATIONS) {
      this.counts.annotationsLost++;
      return;
    }
    this.pending.push({ t, text });
  }

  /** Writes every complete record; `force` writes one even if some input lags (padding it). */
  private flush(force: boolean): number {
    let n = 0;
    if (force) {
      this.padLagging();
      this.writeRecord();
      n++;
    }
    while (this.complete()) {
      this.writeRecord();
      n++;
    }
    return n;
  }

  private complete(): boolean {
    return this.queues.every((q, k) => q.count >= this.opts.inputs[k]!.samplesPerRecord);
  }

  private padLagging(): void {
    this.queues.forEach((q, k) => {
      const need = this.opts.inputs[k]!.samplesPerRecord - q.count;
      if (need <= 0) return;
      if (q.free() < need) q.compact();
      q.pad(need);
      q.debt += need;
      this.counts.padded += need;
    });
  }

  private writeRecord(): void {
    if (!this.headerWritten) this.writeHeader();
    const bps = FORMATS[this.opts.format].bytes;
    let at = 0;
    this.queues.forEach((q, k) => {
      const n = this.opts.inputs[k]!.samplesPerRecord;
      for (let c = 0; c < q.channels; c++) {
        at = this.encode(q, k, c, n, at, bps);
      }
      q.take(n);
    });
    this.writeAnnotations();
    this.sink.write(this.record);
    this.counts.records++;
  }

  /** Channel `c`'s `n` queued samples as digital values at byte `at`; returns the next byte. */
  private encode(q: InputQueue, k: number, c: number, n: number, at: number, bps: number): number {
    const { digitalMin: dmin, digitalMax: dmax } = FORMATS[this.opts.format];
    const lo = this.lo[k]![c]!;
    const g = this.gain[k]![c]!;
    const v = q.values;
    const rec = this.record;
    const C = q.channels;
    let i = q.head * C + c;
    for (let s = 0; s < n; s++, i += C) {
      const x = v[i]!;
      let d = Math.round((x - lo) * g + dmin);
      if (!(d >= dmin)) {
        if (Number.isNaN(x)) this.counts.nan++;
        else this.counts.clipped++;
        d = dmin;
      } else if (d > dmax) {
        this.counts.clipped++;
        d = dmax;
      }
      rec[at++] = d & 0xff;
      rec[at++] = (d >> 8) & 0xff;
      if (bps === 3) rec[at++] = (d >> 16) & 0xff;
    }
    return at;
  }

  private writeAnnotations(): void {
    const rec = this.record;
    const start = this.annotationOffset;
    rec.fill(0, start);
    const onset = this.startFracUs + this.counts.records * this.opts.recordUs;
    let p = writeTal(rec, start, rec.length, onset, "");
    while (this.pending.length > 0) {
      const a = this.pending[0]!;
      const us = Math.round((a.t - this.startWhole) * 1e6);
      const next = writeTal(rec, p, rec.length, us, a.text);
      if (next < 0) break;
      p = next;
      this.pending.shift();
      this.counts.annotations++;
    }
  }

  private writeHeader(): void {
    const fmt = FORMATS[this.opts.format];
    const starts = this.queues.map((q) => q.first).filter((t) => Number.isFinite(t));
    this.start = starts.length > 0 ? Math.min(...starts) : 0;
    this.startWhole = Math.floor(this.start);
    this.startFracUs = Math.round((this.start - this.startWhole) * 1e6);
    if (this.startFracUs >= 1e6) {
      this.startWhole += 1;
      this.startFracUs -= 1e6;
    }
    const signals: EdfSignalSpec[] = [];
    this.opts.inputs.forEach((input, k) => this.scaleInput(input, k, signals));
    signals.push({
      label: fmt.annotationLabel,
      transducer: "",
      dimension: "",
      physicalMin: -1,
      physicalMax: 1,
      digitalMin: fmt.digitalMin,
      digitalMax: fmt.digitalMax,
      prefiltering: "",
      samples: this.opts.annotationBytes / fmt.bytes,
    });
    const header = buildEdfHeader({
      format: this.opts.format,
      patient: this.opts.patient,
      recording: this.opts.recording,
      start: this.startWhole,
      recordDuration: this.opts.recordText,
      records: 0,
      signals,
    });
    this.sink.write(header);
    this.headerWritten = true;
  }

  /** The header's signals of input `k`, and the scale its samples are written with. */
  private scaleInput(input: EdfStreamInput, k: number, out: EdfSignalSpec[]): void {
    const fmt = FORMATS[this.opts.format];
    const q = this.queues[k]!;
    const auto =
      input.ranges === null
        ? autoRange(q.values, q.head * q.channels, (q.head + input.samplesPerRecord) * q.channels)
        : null;
    const lo = new Float64Array(input.channels);
    const gain = new Float64Array(input.channels);
    for (let c = 0; c < input.channels; c++) {
      const [a, b] = auto ?? input.ranges![c]!;
      const spec: EdfSignalSpec = {
        label: input.labels[c]!,
        transducer: "",
        dimension: input.dimensions[c]!,
        physicalMin: a,
        physicalMax: b,
        digitalMin: fmt.digitalMin,
        digitalMax: fmt.digitalMax,
        prefiltering: "",
        samples: input.samplesPerRecord,
      };
      out.push(spec);
      // The scale of the numbers as written (8 characters), which is what readers use.
      const [pmin, pmax] = writtenRange(a, b);
      lo[c] = pmin;
      gain[c] = (fmt.digitalMax - fmt.digitalMin) / (pmax - pmin);
    }
    this.lo[k] = lo;
    this.gain[k] = gain;
  }

  private updateCount(): void {
    this.sink.writeAt(recordsField(this.counts.records, this.countField), RECORDS_OFFSET);
  }

  /** True once the header is written (the file opens from then on). */
  get started(): boolean {
    return this.headerWritten;
  }
}

/** The physical range as the header holds it (rounded outward to 8 characters). */
export function writtenRange(min: number, max: number): [number, number] {
  return [Number(edfNumber(min, 8, "down")), Number(edfNumber(max, 8, "up"))];
}
