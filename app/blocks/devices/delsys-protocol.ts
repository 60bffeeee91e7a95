/**
 * The Delsys Trigno SDK's wire formats (docs/protocols.md, "Delsys Trigno"): the Trigno Control
 * Utility (TCU) serves a command port (ASCII commands and replies, each ended by "\r\n\r\n") and
 * data ports; the Avanti EMG port carries, per sample, 16 float32 little-endian values (one per
 * sensor slot, in volts), sample after sample with no header. A TCP stream has no boundaries, so
 * `TrignoEmgParser` keeps the 64-byte alignment across chunks and, because nothing in the stream
 * marks a sample's start, recognises misalignment by its values (not finite, beyond any sensor's
 * range, or non-zero in an unpaired slot) and finds the alignment again. `DeviceClock` stamps
 * samples on the device's sample clock. The connection itself is `TrignoLink` (delsys-link.ts).
 */

/** The TCU's command port (configurable in its GUI). */
export const TRIGNO_COMMAND_PORT = 50040;
/** The TCU's Avanti EMG data port (legacy sensors: 50041). */
export const TRIGNO_EMG_PORT = 50043;
/** Sensor slots of a Trigno base (and floats per EMG sample on the Avanti port). */
export const TRIGNO_SENSORS = 16;
/** Bytes of one EMG sample on the Avanti port: 16 × float32. */
export const TRIGNO_SAMPLE_BYTES = TRIGNO_SENSORS * 4;
/** The TCU's frame interval, s: every rate is k / 13.5 ms. */
export const TRIGNO_FRAME_INTERVAL = 0.0135;
/** EMG samples per frame with backwards compatibility and upsampling off. */
export const TRIGNO_NATIVE_SAMPLES = 26;
/** The native Avanti EMG rate: 26 / 13.5 ms = 1925.926 Hz. */
export const TRIGNO_NATIVE_RATE = TRIGNO_NATIVE_SAMPLES / TRIGNO_FRAME_INTERVAL;
/**
 * Beyond this magnitude (V) a value cannot be EMG: Trigno sensors span ±11 mV (±22 mV in their
 * widest mode), so a misaligned stream's garbage floats show up here.
 */
export const TRIGNO_MAX_VOLTS = 0.1;
/** The TCU's Avanti AUX (IMU) data port (legacy sensors' accelerometers: 50042). */
export const TRIGNO_AUX_PORT = 50044;
/** Values per sensor slot on the AUX port: accelerometer, gyroscope, magnetometer x, y, z. */
export const TRIGNO_AUX_PER_SLOT = 9;
/** AUX samples per frame (148.148 Hz). */
export const TRIGNO_AUX_SAMPLES = 2;
/**
 * Beyond this magnitude a value cannot be an IMU reading (accelerometers span ±16 g, gyroscopes
 * ±2000 °/s, magnetometers about ±4900 µT): a misaligned AUX stream's garbage shows up here.
 */
export const TRIGNO_MAX_AUX = 1e5;
/** Command terminator (commands and replies). */
export const TRIGNO_TERMINATOR = "\r\n\r\n";

/** Hz with three decimals, as the TCU's rates are written: "1925.926 Hz". */
export const hzText = (hz: number): string => `${(Math.round(hz * 1000) / 1000).toFixed(3)} Hz`;

/**
 * Below this magnitude a non-zero value is no reading either (a sensor's quantised values are
 * far larger): a stream misaligned by 1–3 bytes makes such tiny floats from its bytes.
 */
const TINY = 1e-30;
/** Whole samples needed after a candidate alignment before it is trusted. */
const RESYNC_SAMPLES = 3;
/** Bytes kept while searching for the alignment before a sample's worth is given up. */
const RESYNC_WINDOW_SAMPLES = 32;

/** What a data port carries per sample: values per sensor slot and their plausible range. */
export interface TrignoStreamKind {
  /** "EMG" or "AUX", for messages. */
  name: string;
  perSlot: number;
  maxAbs: number;
  unit: string;
}

export const TRIGNO_EMG: TrignoStreamKind = {
  name: "EMG",
  perSlot: 1,
  maxAbs: TRIGNO_MAX_VOLTS,
  unit: " V",
};
export const TRIGNO_AUX: TrignoStreamKind = {
  name: "AUX",
  perSlot: TRIGNO_AUX_PER_SLOT,
  maxAbs: TRIGNO_MAX_AUX,
  unit: "",
};

/**
 * Splits the EMG port's byte stream into samples of 16 values. `onSample(values)` gets each
 * plausible sample (`values` is reused: copy what you keep). Implausible data is counted
 * (`malformed`: episodes; `skippedBytes`) and skipped until `RESYNC_SAMPLES` plausible samples in a
 * row start at some byte offset. A 4-byte (whole float) shift with every slot paired cannot be
 * seen in the values and goes undetected (docs/protocols.md).
 */
export class TrignoEmgParser {
  /** Bytes of one sample: 16 slots × values per slot × float32. */
  readonly sampleBytes: number;
  private readonly perSample: number;
  private buf: Uint8Array;
  private view: DataView;
  private len = 0;
  private inBadRun = false;
  private readonly values: Float64Array;
  /** Slots (0-based) that must carry exactly 0: the unpaired sensors, when known. */
  private zero = new Uint8Array(TRIGNO_SENSORS);
  samples = 0;
  malformed = 0;
  skippedBytes = 0;
  /** Why the last malformed sample was refused. */
  lastProblem = "";

  constructor(
    private readonly onSample: (values: Float64Array) => void,
    private readonly kind: TrignoStreamKind = TRIGNO_EMG,
  ) {
    this.perSample = TRIGNO_SENSORS * kind.perSlot;
    this.sampleBytes = this.perSample * 4;
    this.values = new Float64Array(this.perSample);
    this.buf = new Uint8Array(this.sampleBytes * 64);
    this.view = new DataView(this.buf.buffer);
  }

  /** Marks the slots of unpaired sensors (1-based numbers): their values must be 0. */
  setUnpaired(sensors: Iterable<number>): void {
    this.zero.fill(0);
    for (const s of sensors) this.zero[s - 1] = 1;
  }

  /** Why the sample at byte `at` is implausible; undefined when it is plausible. */
  private problem(at: number): string | undefined {
    const { perSlot, maxAbs, unit } = this.kind;
    for (let i = 0; i < this.perSample; i++) {
      const v = this.view.getFloat32(at + 4 * i, true);
      const s = Math.floor(i / perSlot);
      const where =
        perSlot === 1 ? `sensor ${s + 1}` : `sensor ${s + 1} value ${(i % perSlot) + 1}`;
      if (!Number.isFinite(v)) return `${where}: ${v}`;
      const m = Math.abs(v);
      if (m > maxAbs || (m < TINY && m !== 0)) return `${where}: ${v.toPrecision(3)}${unit}`;
      if (this.zero[s] === 1 && v !== 0) return `unpaired ${where}: ${v.toPrecision(3)}${unit}`;
    }
    return undefined;
  }

  private plausibleRun(at: number): boolean {
    for (let i = 0; i < RESYNC_SAMPLES; i++) {
      if (this.problem(at + i * this.sampleBytes) !== undefined) return false;
    }
    return true;
  }

  private append(chunk: Uint8Array): void {
    const need = this.len + chunk.length;
    if (need > this.buf.length) {
      const bigger = new Uint8Array(Math.max(need, this.buf.length * 2));
      bigger.set(this.buf.subarray(0, this.len));
      this.buf = bigger;
      this.view = new DataView(bigger.buffer);
    }
    this.buf.set(chunk, this.len);
    this.len = need;
  }

  /** Takes the next bytes of the stream; returns how many samples went to `onSample`. */
  feed(chunk: Uint8Array): number {
    this.append(chunk);
    const before = this.samples;
    const B = this.sampleBytes;
    let pos = 0;
    while (this.len - pos >= B) {
      const why = this.problem(pos);
      if (why === undefined) {
        this.inBadRun = false;
        for (let i = 0; i < this.perSample; i++) {
          this.values[i] = this.view.getFloat32(pos + 4 * i, true);
        }
        this.samples++;
        this.onSample(this.values);
        pos += B;
        continue;
      }
      if (!this.inBadRun) {
        this.inBadRun = true;
        this.malformed++;
        this.lastProblem = why;
      }
      // Look for the offset at which the stream makes sense again.
      const window = B - 1 + RESYNC_SAMPLES * B;
      if (this.len - pos < window + 1) break; // wait for more bytes
      let shift = 0;
      for (let o = 1; o < B; o++) {
        if (this.plausibleRun(pos + o)) {
          shift = o;
          break;
        }
      }
      if (shift === 0) shift = B; // nothing fits here: give this sample up
      this.skippedBytes += shift;
      pos += shift;
      const keep = RESYNC_WINDOW_SAMPLES * B;
      if (this.len - pos > keep) {
        // Garbage for a while: drop all but the last window.
        const drop = this.len - pos - keep;
        this.skippedBytes += drop;
        pos += drop;
      }
    }
    if (pos > 0) {
      this.buf.copyWithin(0, pos, this.len);
      this.len -= pos;
    }
    return this.samples - before;
  }

  /** Bytes held that do not make a whole sample. */
  get pending(): number {
    return this.len;
  }

  /** Forgets held bytes (a new connection starts aligned); returns how many there were. */
  reset(): number {
    const held = this.len;
    this.len = 0;
    this.inBadRun = false;
    return held;
  }

  /** Clears the counters too. */
  resetCounts(): void {
    this.samples = 0;
    this.malformed = 0;
    this.skippedBytes = 0;
    this.lastProblem = "";
  }
}

/**
 * Timestamps on the device's sample clock: the first batch after (re)connecting is placed so
 * that its last sample falls at its arrival on the pipeline clock, every later sample 1 / rate
 * after the one before, whatever the network's jitter. Stamps run ahead of arrival by at most
 * `ahead` (one TCU frame: a batch that comes earlier than that pulls them back, no further than
 * the previous stamp; a device clock faster than the computer's is followed that way) and a
 * stream that falls more than `maxLag` behind (a stall) is re-anchored; both the re-anchorings and
 * the time a reconnection lost are counted.
 */
export class DeviceClock {
  private next = NaN;
  private last = NaN;
  private period: number;
  /** Reconnections after which the stream went on (each a gap). */
  gaps = 0;
  /** Time lost to those gaps, s, and the samples it would have held. */
  gapSeconds = 0;
  gapSamples = 0;
  /** Re-anchorings after a stall. */
  reanchors = 0;

  constructor(
    private rate: number,
    readonly maxLag = 0.5,
    readonly ahead = TRIGNO_FRAME_INTERVAL,
  ) {
    this.period = 1 / rate;
  }

  setRate(rate: number): void {
    this.rate = rate;
    this.period = 1 / rate;
  }

  /** Fills t[0…n) for n samples that arrived together at `now`. */
  stamp(now: number, t: Float64Array, n: number): void {
    const p = this.period;
    const span = (n - 1) * p;
    let first: number;
    if (this.next !== this.next) {
      first = now - span;
      if (this.last === this.last) {
        // After a reconnection: the time between the old stream's end and this one is a gap.
        const gap = first - (this.last + p);
        this.gaps++;
        if (gap > 0) {
          this.gapSeconds += gap;
          this.gapSamples += Math.round(gap * this.rate);
        }
        if (first <= this.last) first = this.last + p;
      }
    } else {
      first = this.next;
      if (first + span > now + this.ahead) first = Math.max(now + this.ahead - span, this.last);
      else if (now - (first + span) > this.maxLag) {
        first = now - span;
        this.reanchors++;
      }
    }
    for (let i = 0; i < n; i++) t[i] = first + i * p;
    this.last = first + span;
    this.next = this.last + p;
  }

  /** The stream broke: the next batch anchors again (and the time in between is a gap). */
  restart(): void {
    this.next = NaN;
  }

  /** Forgets everything (a new run). */
  reset(): void {
    this.next = NaN;
    this.last = NaN;
    this.gaps = 0;
    this.gapSeconds = 0;
    this.gapSamples = 0;
    this.reanchors = 0;
  }
}
