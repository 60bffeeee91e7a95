/**
 * Joins a Trigno's two data streams into one output (docs/protocols.md, "Delsys Trigno"): the EMG
 * port's samples (26 per 13.5 ms frame) and the AUX port's IMU samples (2 per frame). Both count
 * from 0 at START on the TCU's frame clock, so EMG sample i belongs with AUX sample
 * ⌊i · auxPerFrame / emgPerFrame⌋ (the AUX sample whose part of the frame it falls in; the
 * accelerometer is held for 13 EMG samples). Output per selected sensor, in the order of
 * `Sensors`: its EMG value, then its first `perSensor` AUX values (3: accelerometer x, y, z in g;
 * 9: accelerometer, gyroscope, magnetometer).
 *
 * The TCU sends a frame's EMG and AUX data at the same time on two connections, so one usually
 * arrives a little before the other: EMG samples wait for their AUX sample, AUX samples wait for
 * their EMG samples. An AUX stream more than `MAX_WAIT` frames behind lets the EMG go on with
 * the last AUX values held (counted: `held`); AUX samples more than `MAX_WAIT` frames ahead of the
 * EMG are dropped (counted: `dropped`). Nothing else is lost or duplicated.
 */

/** Frames one stream may run ahead of the other before the join stops waiting. */
export const MAX_WAIT = 8;

export interface AuxJoinCounts {
  /** EMG samples that went out with held AUX values (their own AUX sample was late or lost). */
  held: number;
  /** AUX samples dropped because no EMG sample came for them in time. */
  dropped: number;
}

/** A growable queue of fixed-width rows of float64. */
class RowQueue {
  private buf: Float64Array;
  private head = 0;
  rows = 0;

  constructor(readonly width: number) {
    this.buf = new Float64Array(Math.max(1, width) * 64);
  }

  /** Room for one more row; returns its offset (fill `data` there). */
  push(): number {
    const w = this.width;
    if ((this.head + this.rows + 1) * w > this.buf.length) {
      if (this.head > 0) {
        this.buf.copyWithin(0, this.head * w, (this.head + this.rows) * w);
        this.head = 0;
      }
      if ((this.rows + 1) * w > this.buf.length) {
        const bigger = new Float64Array(this.buf.length * 2);
        bigger.set(this.buf.subarray(0, this.rows * w));
        this.buf = bigger;
      }
    }
    return (this.head + this.rows++) * w;
  }

  get data(): Float64Array {
    return this.buf;
  }

  /** Offset of row r (0: the oldest). */
  at(r: number): number {
    return (this.head + r) * this.width;
  }

  shift(n: number): void {
    this.head += n;
    this.rows -= n;
    if (this.rows === 0) this.head = 0;
  }

  clear(): void {
    this.head = 0;
    this.rows = 0;
  }
}

export class TrignoAuxJoin {
  /** Output values per sample. */
  readonly width: number;
  readonly counts: AuxJoinCounts = { held: 0, dropped: 0 };
  private readonly emg: RowQueue;
  private readonly aux: RowQueue;
  /** Index (since START) of the oldest queued EMG sample and of the oldest queued AUX sample. */
  private emgBase = 0;
  private auxBase = 0;
  /** The AUX values last used (held when the AUX stream falls behind). */
  private readonly last: Float64Array;
  private out: Float64Array;

  /**
   * `slots`: the selected sensors' slots (0-based) in output order; `perSensor`: AUX values kept
   * per sensor; `emgPerFrame` / `auxPerFrame`: samples per 13.5 ms frame of each stream.
   */
  constructor(
    private readonly slots: Int32Array,
    private readonly perSensor: number,
    private emgPerFrame: number,
    private auxPerFrame: number,
    private readonly perSlot = 9,
  ) {
    this.width = slots.length * (1 + perSensor);
    this.emg = new RowQueue(slots.length);
    this.aux = new RowQueue(slots.length * perSensor);
    this.last = new Float64Array(slots.length * perSensor);
    this.out = new Float64Array(this.width * 64);
  }

  /** The samples per frame of a new session (both streams start again at index 0). */
  restart(emgPerFrame: number, auxPerFrame: number): void {
    this.emgPerFrame = emgPerFrame;
    this.auxPerFrame = auxPerFrame;
    this.emg.clear();
    this.aux.clear();
    this.emgBase = 0;
    this.auxBase = 0;
    this.last.fill(0);
  }

  /** One EMG sample (16 slot values). */
  pushEmg(values: Float64Array): void {
    const at = this.emg.push();
    const d = this.emg.data;
    for (let i = 0; i < this.slots.length; i++) d[at + i] = values[this.slots[i]!]!;
  }

  /** One AUX sample (16 × perSlot values). */
  pushAux(values: Float64Array): void {
    const at = this.aux.push();
    const d = this.aux.data;
    const a = this.perSensor;
    for (let i = 0; i < this.slots.length; i++) {
      const from = this.slots[i]! * this.perSlot;
      for (let j = 0; j < a; j++) d[at + i * a + j] = values[from + j]!;
    }
  }

  /** The AUX sample index EMG sample `i` belongs with. */
  private auxIndexOf(i: number): number {
    return Math.floor((i * this.auxPerFrame) / this.emgPerFrame);
  }

  /**
   * Joins every EMG sample whose AUX sample is there (or waited too long); returns the rows
   * (valid until the next call) and how many.
   */
  drain(): { values: Float64Array; n: number } {
    const k = this.slots.length;
    const a = this.perSensor;
    const w = this.width;
    const maxLag = MAX_WAIT * this.auxPerFrame;
    let n = 0;
    while (this.emg.rows > n) {
      const i = this.emgBase + n;
      const j = this.auxIndexOf(i);
      const end = this.auxBase + this.aux.rows;
      // Wait for its AUX sample, unless the EMG has run MAX_WAIT frames ahead of the AUX.
      if (j >= end && this.auxIndexOf(this.emgBase + this.emg.rows - 1) - end < maxLag) break;
      if (j >= end || j < this.auxBase) this.counts.held++;
      else this.takeAux(j - this.auxBase);
      if ((n + 1) * w > this.out.length) {
        const bigger = new Float64Array(this.out.length * 2);
        bigger.set(this.out.subarray(0, n * w));
        this.out = bigger;
      }
      const e = this.emg.data;
      const ea = this.emg.at(n);
      for (let s = 0; s < k; s++) {
        const o = n * w + s * (1 + a);
        this.out[o] = e[ea + s]!;
        for (let c = 0; c < a; c++) this.out[o + 1 + c] = this.last[s * a + c]!;
      }
      n++;
    }
    this.emg.shift(n);
    this.emgBase += n;
    this.forgetUsedAux();
    return { values: this.out, n };
  }

  /** Makes queued AUX row r the values joined (and held) from now on. */
  private takeAux(r: number): void {
    const from = this.aux.at(r);
    this.last.set(this.aux.data.subarray(from, from + this.last.length));
  }

  /** Drops AUX samples no EMG sample needs any more, and those too far ahead of the EMG. */
  private forgetUsedAux(): void {
    const needed = this.auxIndexOf(this.emgBase);
    let drop = Math.max(0, Math.min(this.aux.rows, needed - this.auxBase));
    const ahead = this.aux.rows - drop - MAX_WAIT * this.auxPerFrame;
    if (ahead > 0) {
      this.counts.dropped += ahead;
      drop += ahead;
    }
    if (drop === 0) return;
    this.aux.shift(drop);
    this.auxBase += drop;
  }
}
