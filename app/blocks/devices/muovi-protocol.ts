/**
 * OT Bioelettronica's Muovi probes and SyncStation on the wire (docs/protocols.md, "OT
 * Bioelettronica Muovi and SyncStation"): the commands the PC sends and the sample stream it gets.
 *
 * - **SyncStation** (the PC is a TCP client of 192.168.76.1:54320): one configuration command,
 *   `[count·2 + GO, probe bytes…, CRC-8]`, a probe byte being `slot·16 + EMG·8 + mode·2 + enable`;
 *   stop is `[0, CRC-8 of it]`. Then, per sample at 2 kHz, the enabled slots' channels in slot order
 *   (38 int16 big-endian per Muovi: 32 EMG, 4 IMU quaternion, buffer/trigger, sample counter)
 *   followed by the SyncStation's own 6 channels, the last of them its sample counter.
 * - **Muovi alone** (the probe is a TCP client of the PC's port 54321): one command byte,
 *   `EMG·8 + mode·2 + GO` (9: EMG at 2 kHz, 32 monopolar channels, start; 8: stop), then 38 int16
 *   big-endian channels per sample, the last the probe's sample counter.
 *
 * Nothing in the stream marks where a sample starts: `MuoviStreamParser` keeps the alignment by the
 * last channel, which counts samples (+1 per sample, wrapping at 16 bits), finds it again after
 * malformed bytes and counts samples the device skipped.
 */

/** The SyncStation's address on its own Wi-Fi network and its TCP port (the original's). */
export const MUOVI_HOST = "192.168.76.1";
export const MUOVI_PORT = 54320;
/** EMG channels per probe, and the probes' EMG sampling rate (Hz). */
export const MUOVI_CHANNELS = 32;
export const MUOVI_RATE = 2000;
/** The local TCP port a single probe connects to (the original's MuoviSingleProbe listened here). */
export const MUOVI_PROBE_PORT = 54321;
/** Channels a Muovi sends per sample in EMG mode (32 EMG + 4 quaternion + buffer + counter). */
export const MUOVI_WIRE_CHANNELS = 38;
/** The SyncStation's own channels after the probes' (3 AUX, load cell, buffer, counter). */
export const SYNCSTATION_CHANNELS = 6;
/** Muovi slots on a SyncStation (0-based 0…3; 4-5 are Muovi+/Sessantaquattro+, 6… Due+/Quattro+). */
export const SYNCSTATION_MUOVI_SLOTS = 4;
/** Muovi EMG mode, 32 monopolar channels with preamp gain 8: 286.1 nV per bit, in mV. */
export const MUOVI_MV_PER_BIT = 0.000286;
/** The original Muovi block's unit: raw / 32768. */
export const MUOVI_FULL_SCALE = 32768;

/**
 * CRC-8 of `bytes[0…len)` as OT Bioelettronica's examples compute it: least significant bit
 * first, 0x8C (the reflected polynomial x⁸ + x⁵ + x⁴ + 1, 0x31) xored in when the bit out differs,
 * initial value 0: the CRC-8/MAXIM (Dallas 1-Wire) checksum.
 */
export function crc8(bytes: ArrayLike<number>, len = bytes.length): number {
  let crc = 0;
  for (let i = 0; i < len; i++) {
    let b = bytes[i]! & 0xff;
    for (let k = 0; k < 8; k++) {
      const out = (crc ^ b) & 1;
      crc >>= 1;
      if (out) crc ^= 0x8c;
      b >>= 1;
    }
  }
  return crc;
}

/** The probe byte of one SyncStation slot (EMG mode, 32 monopolar channels, enabled). */
export function syncStationProbeByte(slot: number): number {
  return slot * 16 + 1 * 8 + 0 * 2 + 1;
}

/** The SyncStation's start command for these Muovi slots (0…3, any order): sorted, CRC-8 last. */
export function syncStationStart(slots: readonly number[]): Uint8Array {
  const sorted = [...slots].sort((a, b) => a - b);
  for (const s of sorted) {
    if (!Number.isInteger(s) || s < 0 || s >= SYNCSTATION_MUOVI_SLOTS) {
      throw new Error(
        `SyncStation slot ${s} is not a Muovi slot (0…${SYNCSTATION_MUOVI_SLOTS - 1})`,
      );
    }
  }
  const cmd = new Uint8Array(sorted.length + 2);
  cmd[0] = sorted.length * 2 + 1;
  sorted.forEach((s, i) => (cmd[i + 1] = syncStationProbeByte(s)));
  cmd[cmd.length - 1] = crc8(cmd, cmd.length - 1);
  return cmd;
}

/** The SyncStation's stop command: a header of 0 (no probes, GO off) and its CRC-8. */
export function syncStationStop(): Uint8Array {
  return Uint8Array.of(0, crc8([0]));
}

/** A single Muovi's command byte: EMG mode, 32 monopolar channels, GO (start) or not (stop). */
export function probeCommand(go: boolean): number {
  return 1 * 8 + 0 * 2 + (go ? 1 : 0);
}

/** Channels per sample of a SyncStation streaming `probes` Muovi probes. */
export const syncStationChannels = (probes: number): number =>
  probes * MUOVI_WIRE_CHANNELS + SYNCSTATION_CHANNELS;

/** Whole samples in a row whose counters follow each other before an alignment is trusted. */
export const LOCK_SAMPLES = 3;
/** The largest jump of the counter taken for samples the device skipped (1 s at 2 kHz). */
export const MAX_GAP = 2000;

/**
 * Splits an int16 big-endian stream of `channels` values per sample into samples, aligned by the
 * last channel (a counter, +1 per sample). `onSample(raw)` gets each sample's values (reused:
 * copy what you keep). A counter that jumps ahead and goes on counting from there is a gap
 * (`lostSamples`; a jump back or beyond MAX_GAP that counts on for LOCK_SAMPLES is a restart,
 * `counterJumps`); one that does not is misalignment: counted (`malformed`, once per episode),
 * bytes skipped (`skippedBytes`) until `LOCK_SAMPLES` samples in a row count again.
 */
export class MuoviStreamParser {
  readonly sampleBytes: number;
  private buf: Uint8Array;
  private len = 0;
  private expected = -1;
  private inBadRun = false;
  private readonly raw: Int16Array;
  samples = 0;
  lostSamples = 0;
  /** Times the counter restarted or jumped by more than MAX_GAP and counted on from there. */
  counterJumps = 0;
  malformed = 0;
  skippedBytes = 0;
  lastProblem = "";

  constructor(
    readonly channels: number,
    private readonly onSample: (raw: Int16Array) => void,
  ) {
    if (!Number.isInteger(channels) || channels < 2) {
      throw new Error(`a Muovi stream has at least 2 channels per sample, not ${channels}`);
    }
    this.sampleBytes = channels * 2;
    this.raw = new Int16Array(channels);
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
    if (this.len + chunk.length > this.buf.length) {
      let size = this.buf.length;
      while (size < this.len + chunk.length) size *= 2;
      const bigger = new Uint8Array(size);
      bigger.set(this.buf.subarray(0, this.len));
      this.buf = bigger;
    }
    this.buf.set(chunk, this.len);
    this.len += chunk.length;
    const used = this.drain();
    this.buf.copyWithin(0, used, this.len);
    this.len -= used;
  }

  /** The counter (u16) of the sample starting at byte `at`. */
  private counter(at: number): number {
    const i = at + this.sampleBytes - 2;
    return (this.buf[i]! << 8) | this.buf[i + 1]!;
  }

  /** The first offset ≥ `from` where LOCK_SAMPLES counters follow each other, or -1. */
  private findLock(from: number): number {
    const S = this.sampleBytes;
    for (let o = from; o + LOCK_SAMPLES * S <= this.len; o++) {
      let ok = true;
      for (let k = 1; k < LOCK_SAMPLES && ok; k++) {
        ok = this.counter(o + k * S) === ((this.counter(o) + k) & 0xffff);
      }
      if (ok) return o;
    }
    return -1;
  }

  private misaligned(why: string): void {
    if (this.inBadRun) return;
    this.malformed++;
    this.inBadRun = true;
    this.lastProblem = why;
  }

  /** Consumes whole samples; returns the bytes used. */
  private drain(): number {
    const S = this.sampleBytes;
    let at = 0;
    while (this.len - at >= S) {
      if (this.expected < 0) {
        if (this.len - at < LOCK_SAMPLES * S) break;
        const o = this.findLock(at);
        if (o < 0) {
          // Keep what could still start an aligned run; the rest is skipped.
          const skip = this.len - at - (LOCK_SAMPLES * S - 1);
          this.skippedBytes += skip;
          at += skip;
          this.misaligned(
            `no sample counter (the last of ${this.channels} channels, +1 per sample) in the data: not a Muovi stream, or misaligned`,
          );
          break;
        }
        if (o > at) {
          this.misaligned(`${o - at} bytes before the first whole sample`);
          this.skippedBytes += o - at;
        }
        at = o;
        this.expected = this.counter(at);
        this.inBadRun = false;
      }
      const c = this.counter(at);
      if (c !== this.expected) {
        if (this.len - at < 2 * S) break; // the next sample says which
        const gap = (c - this.expected) & 0xffff;
        if (gap <= MAX_GAP && this.counter(at + S) === ((c + 1) & 0xffff)) {
          this.lostSamples += gap;
        } else if (this.len - at < LOCK_SAMPLES * S) {
          break; // a restarted counter or misalignment: the next samples say which
        } else if (this.findLock(at) === at) {
          // The counter restarted (or jumped further than a gap) and counts on, aligned.
          this.counterJumps++;
        } else {
          this.misaligned(
            `sample counter ${c} where ${this.expected} was due and no count follows: misaligned`,
          );
          this.expected = -1;
          this.skippedBytes++;
          at++;
          continue;
        }
      }
      const b = this.buf;
      for (let ch = 0; ch < this.channels; ch++) {
        const i = at + 2 * ch;
        this.raw[ch] = (b[i]! << 8) | b[i + 1]!;
      }
      this.expected = (c + 1) & 0xffff;
      this.samples++;
      at += S;
      this.onSample(this.raw);
    }
    return at;
  }
}

/** Where each requested slot's channels start in a SyncStation sample (slots stream in slot order). */
export function slotOffsets(slots: readonly number[]): number[] {
  const sorted = [...slots].sort((a, b) => a - b);
  return slots.map((s) => sorted.indexOf(s) * MUOVI_WIRE_CHANNELS);
}
