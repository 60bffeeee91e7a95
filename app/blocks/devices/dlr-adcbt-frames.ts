/**
 * The DLR ADC/BT's bytes, as the original MOSAIC's `DLR_ADCBT` block wrote and read them
 * (docs/protocols.md, "DLR ADC/BT"): 19-byte commands (the channel count, start and stop of the
 * stream) and fixed-size frames `AA 7A len ? | channels × u16 big-endian | ? ? FF FF` with
 * len = 4 + 2·channels + 4, each value in volts as 5 · raw / 4000.
 *
 * `DlrFrameParser` finds frames in bytes as the serial port delivers them (chunk boundaries mean
 * nothing): it re-synchronises on the start bytes, counts what it had to throw away (a wrong
 * length byte, a bad end mark, bytes before a start) and never throws on input. Pure: no I/O.
 */
import { plural } from "../shared/text";

/** The two bytes that start every frame and every command. */
export const DLR_START = [0xaa, 0x7a] as const;
/** The last two bytes of a frame. */
export const DLR_END = [0xff, 0xff] as const;
/** Bytes of a command. */
export const DLR_COMMAND_LENGTH = 19;
/** The original's scale: raw / 4000 · 5 V. */
export const DLR_VOLTS_PER_COUNT = 5 / 4000;

/** A frame's length in bytes for `channels` channels (its length byte). */
export function dlrFrameLength(channels: number): number {
  return 4 + 2 * channels + 4;
}

/** A raw 16-bit value in volts, computed as the original did: 5.0 · raw / 4000.0. */
export function dlrVolts(raw: number): number {
  return (5.0 * raw) / 4000.0;
}

/** The command codes (bytes 2 and 3 of a command). */
const COMMANDS = {
  channels: [0x03, 0x01],
  start: [0x01, 0x6a],
  stop: [0x01, 0x6b],
} as const;
/** The bytes every command ends with (15…18). */
const COMMAND_TAIL = [0x01, 0x8f, 0xff, 0xef] as const;

export type DlrCommand = keyof typeof COMMANDS;

/**
 * A 19-byte command: start bytes, code, byte 4 (the channel count for `channels`, 0 otherwise),
 * zeros, then 01 8F FF EF.
 */
export function dlrCommand(kind: DlrCommand, channels = 0): Uint8Array {
  if (kind === "channels" && !(Number.isInteger(channels) && channels >= 1 && channels <= 255)) {
    throw new RangeError(`a channel count is one byte, 1…255; got ${channels}`);
  }
  const c = new Uint8Array(DLR_COMMAND_LENGTH);
  c.set(DLR_START, 0);
  c.set(COMMANDS[kind], 2);
  if (kind === "channels") c[4] = channels;
  c.set(COMMAND_TAIL, DLR_COMMAND_LENGTH - COMMAND_TAIL.length);
  return c;
}

/** What the parser has seen since it was created or reset. */
export interface DlrParserStats {
  /** Frames decoded. */
  frames: number;
  /** Frames thrown away: a wrong length byte or a bad end mark (a short or corrupted frame). */
  malformed: number;
  /** Of those, frames whose length byte was not the expected one. */
  badLength: number;
  /** Of those, frames without FF FF at their end (truncated, or bytes lost or changed). */
  badEnd: number;
  /** Bytes skipped while looking for a start (between frames, or the rest of a malformed one). */
  skipped: number;
  /** The last problem, in words ("" when none). */
  lastProblem: string;
}

const hex = (b: number): string => b.toString(16).toUpperCase().padStart(2, "0");

/** Finds frames of one channel count in a byte stream (see the file comment). */
export class DlrFrameParser {
  readonly frameLength: number;
  readonly stats: DlrParserStats = {
    frames: 0,
    malformed: 0,
    badLength: 0,
    badEnd: 0,
    skipped: 0,
    lastProblem: "",
  };
  private buf: Uint8Array;
  private len = 0;
  private readonly values: Float64Array;

  constructor(readonly channels: number) {
    if (!(Number.isInteger(channels) && channels >= 1 && dlrFrameLength(channels) <= 255)) {
      throw new RangeError(
        `the DLR ADC/BT's frame length is one byte: 1…123 channels, not ${channels}`,
      );
    }
    this.frameLength = dlrFrameLength(channels);
    this.buf = new Uint8Array(4 * this.frameLength);
    this.values = new Float64Array(channels);
  }

  /**
   * Takes the next bytes; calls `onFrame` with the values in volts (a view reused for the next
   * frame: copy what you keep) for every complete frame they finish.
   */
  push(bytes: Uint8Array, onFrame: (volts: Float64Array) => void): void {
    this.append(bytes);
    const b = this.buf;
    const L = this.frameLength;
    let at = 0;
    while (at < this.len) {
      const start = this.findStart(at);
      if (start < 0) {
        // Keep a last AA: it may be the first half of a start.
        const keep = b[this.len - 1] === DLR_START[0] ? 1 : 0;
        this.stats.skipped += this.len - keep - at;
        at = this.len - keep;
        break;
      }
      this.stats.skipped += start - at;
      at = start;
      if (this.len - at < 3) break;
      const length = b[at + 2]!;
      if (length !== L) {
        this.reject(
          "badLength",
          `length byte ${length}, expected ${L} (${plural(this.channels, "channel")})`,
        );
        at++;
        continue;
      }
      if (this.len - at < L) break;
      if (b[at + L - 2] !== DLR_END[0] || b[at + L - 1] !== DLR_END[1]) {
        this.reject(
          "badEnd",
          `end mark ${hex(b[at + L - 2]!)} ${hex(b[at + L - 1]!)}, expected FF FF (a short or corrupted frame)`,
        );
        at++;
        continue;
      }
      for (let c = 0; c < this.channels; c++) {
        const i = at + 4 + 2 * c;
        this.values[c] = dlrVolts(256 * b[i]! + b[i + 1]!);
      }
      this.stats.frames++;
      at += L;
      onFrame(this.values);
    }
    b.copyWithin(0, at, this.len);
    this.len -= at;
  }

  /** Forgets bytes kept for an unfinished frame (a new connection); the counts stay. */
  clear(): void {
    this.len = 0;
  }

  /** Forgets everything, counts included. */
  reset(): void {
    this.len = 0;
    Object.assign(this.stats, {
      frames: 0,
      malformed: 0,
      badLength: 0,
      badEnd: 0,
      skipped: 0,
      lastProblem: "",
    });
  }

  private reject(kind: "badLength" | "badEnd", problem: string): void {
    this.stats.malformed++;
    this.stats[kind]++;
    this.stats.lastProblem = problem;
    // The start's first byte is skipped; the search resumes right after it.
    this.stats.skipped++;
  }

  /** The index of the next AA 7A from `from` (-1: none complete in the buffer). */
  private findStart(from: number): number {
    const b = this.buf;
    for (let i = from; i + 1 < this.len; i++) {
      if (b[i] === DLR_START[0] && b[i + 1] === DLR_START[1]) return i;
    }
    return -1;
  }

  private append(bytes: Uint8Array): void {
    const need = this.len + bytes.length;
    if (need > this.buf.length) {
      const grown = new Uint8Array(Math.max(need, 2 * this.buf.length));
      grown.set(this.buf.subarray(0, this.len));
      this.buf = grown;
    }
    this.buf.set(bytes, this.len);
    this.len = need;
  }
}
