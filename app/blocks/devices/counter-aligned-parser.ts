/**
 * The sample framing shared by OT Bioelettronica's streams (Muovi/SyncStation, Quattrocento,
 * Sessantaquattro): fixed-size samples with no header, kept aligned by a channel that counts +1
 * per sample (its 16 low bits are compared). Each device says where its counter is and how a
 * sample's values decode (`CounterFraming`); the alignment, gap and restart logic is here, once.
 */
import type { StreamParser } from "./stream-link";

/** Whole samples in a row whose counters follow each other before an alignment is trusted. */
export const LOCK_SAMPLES = 3;

/** What differs between the devices' streams. */
export interface CounterFraming<R extends Int16Array | Int32Array> {
  /** Bytes of one sample on the wire. */
  readonly sampleBytes: number;
  /** The largest jump of the counter taken for samples the device skipped. */
  readonly maxGap: number;
  /** The problem when no counter is found, e.g. "no sample counter (…) in the data: …". */
  readonly noCounter: string;
  /** The 16 low bits of the counter of the sample starting at byte `at` of `buf`. */
  counter(buf: Uint8Array, at: number): number;
  /** The values of the sample starting at byte `at` of `buf` into `raw`. */
  decode(buf: Uint8Array, at: number, raw: R): void;
}

/** 16 bits big-endian at `i`. */
export const u16be = (b: Uint8Array, i: number): number => (b[i]! << 8) | b[i + 1]!;
/** 16 bits little-endian at `i`. */
export const u16le = (b: Uint8Array, i: number): number => b[i]! | (b[i + 1]! << 8);

/**
 * Splits a stream into samples aligned by their counter. `onSample(raw)` gets each sample's values
 * (reused: copy what you keep). A counter that jumps ahead (at most `maxGap`) and counts on from
 * there is a gap (`lostSamples`); one that jumps back or further and counts on for LOCK_SAMPLES
 * is a restart (`counterJumps`); one that does neither is misalignment: counted (`malformed`,
 * once per episode), bytes skipped (`skippedBytes`) until LOCK_SAMPLES samples in a row count
 * again.
 */
export class CounterAlignedParser<R extends Int16Array | Int32Array> implements StreamParser {
  readonly sampleBytes: number;
  private buf: Uint8Array;
  private len = 0;
  /** The counter due next (16 bits), -1 while the alignment is searched for. */
  private expected = -1;
  private inBadRun = false;
  samples = 0;
  lostSamples = 0;
  /** Times the counter restarted or jumped by more than `maxGap` and counted on from there. */
  counterJumps = 0;
  malformed = 0;
  skippedBytes = 0;
  lastProblem = "";

  constructor(
    private readonly framing: CounterFraming<R>,
    private readonly raw: R,
    private readonly onSample: (raw: R) => void,
  ) {
    this.sampleBytes = framing.sampleBytes;
    this.buf = new Uint8Array(this.sampleBytes * 64);
  }

  /** Bytes held (part of a sample, or a search for the alignment). */
  get held(): number {
    return this.len;
  }

  /** Forgets the alignment and what is held (a new connection); returns the bytes dropped. */
  reset(): number {
    const held = this.len;
    this.len = 0;
    this.expected = -1;
    this.inBadRun = false;
    return held;
  }

  feed(chunk: Uint8Array): void {
    this.append(chunk);
    const used = this.drain();
    this.buf.copyWithin(0, used, this.len);
    this.len -= used;
  }

  private append(chunk: Uint8Array): void {
    const need = this.len + chunk.length;
    if (need > this.buf.length) {
      let size = this.buf.length;
      while (size < need) size *= 2;
      const bigger = new Uint8Array(size);
      bigger.set(this.buf.subarray(0, this.len));
      this.buf = bigger;
    }
    this.buf.set(chunk, this.len);
    this.len = need;
  }

  private counter(at: number): number {
    return this.framing.counter(this.buf, at);
  }

  /** Whether LOCK_SAMPLES counters from `at` follow each other. */
  private countsOn(at: number): boolean {
    const c = this.counter(at);
    for (let k = 1; k < LOCK_SAMPLES; k++) {
      if (this.counter(at + k * this.sampleBytes) !== ((c + k) & 0xffff)) return false;
    }
    return true;
  }

  /** The first offset ≥ `from` where the counters count on, or -1. */
  private findLock(from: number): number {
    const last = this.len - LOCK_SAMPLES * this.sampleBytes;
    for (let o = from; o <= last; o++) if (this.countsOn(o)) return o;
    return -1;
  }

  private misaligned(why: string): void {
    if (this.inBadRun) return;
    this.malformed++;
    this.inBadRun = true;
    this.lastProblem = why;
  }

  /**
   * Finds the alignment from `at`: returns where the aligned samples start, or -1 when the bytes
   * held cannot say yet (with no alignment in them, all but those that could still start one are
   * skipped).
   */
  private lock(at: number): number {
    const keep = LOCK_SAMPLES * this.sampleBytes - 1;
    if (this.len - at <= keep) return -1;
    const o = this.findLock(at);
    if (o < 0) {
      this.skippedBytes += this.len - at - keep;
      this.misaligned(this.framing.noCounter);
      return -1;
    }
    if (o > at) {
      this.misaligned(`${o - at} bytes before the first whole sample`);
      this.skippedBytes += o - at;
    }
    this.expected = this.counter(o);
    this.inBadRun = false;
    return o;
  }

  /**
   * The sample at `at` does not carry the counter due: "take" it (a gap or a restart, counted),
   * "wait" for more bytes, or "realign".
   */
  private judge(at: number, c: number): "take" | "wait" | "realign" {
    const S = this.sampleBytes;
    if (this.len - at < 2 * S) return "wait";
    const gap = (c - this.expected) & 0xffff;
    if (gap <= this.framing.maxGap && this.counter(at + S) === ((c + 1) & 0xffff)) {
      this.lostSamples += gap;
      return "take";
    }
    if (this.len - at < LOCK_SAMPLES * S) return "wait";
    if (this.countsOn(at)) {
      this.counterJumps++;
      return "take";
    }
    this.misaligned(
      `sample counter ${c} where ${this.expected} was due and no count follows: misaligned`,
    );
    return "realign";
  }

  /** Consumes whole samples; returns the bytes used. */
  private drain(): number {
    const S = this.sampleBytes;
    let at = 0;
    while (this.len - at >= S) {
      if (this.expected < 0) {
        const o = this.lock(at);
        if (o < 0) return this.lockSearchEnd(at);
        at = o;
      }
      const c = this.counter(at);
      if (c !== this.expected) {
        const v = this.judge(at, c);
        if (v === "wait") break;
        if (v === "realign") {
          this.expected = -1;
          this.skippedBytes++;
          at++;
          continue;
        }
      }
      this.framing.decode(this.buf, at, this.raw);
      this.expected = (c + 1) & 0xffff;
      this.samples++;
      at += S;
      this.onSample(this.raw);
    }
    return at;
  }

  /** Where the bytes kept after a failed alignment search from `at` begin. */
  private lockSearchEnd(at: number): number {
    const keep = LOCK_SAMPLES * this.sampleBytes - 1;
    return Math.max(at, this.len - keep);
  }
}
