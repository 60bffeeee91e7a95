/**
 * Byte framing for serial devices (the SerialPort block): text lines of numbers, or binary
 * structs with sync bytes and a checksum. Decoders are incremental (chunks may split a frame
 * anywhere), never throw on device data, and count what they had to discard; encoders write
 * outgoing vectors in the same framing.
 */

export const FIELD_TYPES = ["i8", "u8", "i16", "u16", "i32", "u32", "f32", "f64"] as const;
export type FieldType = (typeof FIELD_TYPES)[number];

export const CHECKSUMS = ["none", "xor8", "sum8", "crc16"] as const;
export type Checksum = (typeof CHECKSUMS)[number];

const FIELD_SIZE: Record<FieldType, number> = {
  i8: 1,
  u8: 1,
  i16: 2,
  u16: 2,
  i32: 4,
  u32: 4,
  f32: 4,
  f64: 8,
};

const CHECKSUM_SIZE: Record<Checksum, number> = { none: 0, xor8: 1, sum8: 1, crc16: 2 };

export interface DecodeStats {
  /** Frames decoded. */
  frames: number;
  /** Lines or frames dropped because they were malformed (wrong count, not numbers, bad checksum). */
  malformed: number;
  /** Bytes skipped while looking for the sync bytes. */
  skipped: number;
  /** The last problem, for the block's status. */
  lastProblem: string;
}

export interface Decoder {
  /** Feeds bytes; calls `frame` with each complete vector (reused array: copy it). */
  push(bytes: Uint8Array, frame: (values: Float64Array) => void): void;
  reset(): void;
  readonly stats: DecodeStats;
}

export interface Encoder {
  encode(values: ArrayLike<number>): Uint8Array;
}

function newStats(): DecodeStats {
  return { frames: 0, malformed: 0, skipped: 0, lastProblem: "" };
}

// ---------------------------------------------------------------------------------------------
// Lines

export interface LineOptions {
  /** Values per line. */
  channels: number;
  /** Separators between numbers; a comma, semicolon, tab or spaces by default. */
  separator?: RegExp;
  /** Longest accepted line in bytes; longer ones are dropped as malformed. */
  maxLineBytes?: number;
}

const DEFAULT_SEPARATOR = /[,;\s]+/;

/** One vector per line: `1.5,2,-3` (or separated by `;`, tabs, spaces), `\n` or `\r\n` ended. */
export function lineDecoder(options: LineOptions): Decoder {
  return new LineDecoder(options);
}

/** The line decoder: the start of a line split across chunks is kept until its end arrives. */
class LineDecoder implements Decoder {
  readonly stats = newStats();
  private readonly channels: number;
  private readonly sep: RegExp;
  private readonly maxLine: number;
  /** The vector handed to `frame` (reused). */
  private readonly out: Float64Array;
  /** The line carried over from earlier chunks: `pending[0, used)`. */
  private pending = new Uint8Array(256);
  private used = 0;
  /** The carried line is already longer than `maxLine`: it is dropped when it ends. */
  private overflow = false;

  constructor(options: LineOptions) {
    this.channels = options.channels;
    this.sep = options.separator ?? DEFAULT_SEPARATOR;
    this.maxLine = options.maxLineBytes ?? 4096;
    this.out = new Float64Array(options.channels);
  }

  reset(): void {
    this.used = 0;
    this.overflow = false;
  }

  push(bytes: Uint8Array, frame: (values: Float64Array) => void): void {
    let start = 0;
    for (let i = 0; i < bytes.length; i++) {
      if (bytes[i] !== 0x0a) continue;
      const piece = bytes.subarray(start, i);
      start = i + 1;
      this.endLine(piece, frame);
    }
    this.carry(bytes.subarray(start));
  }

  /** A line ends with `piece` (after what was carried): decodes it, or drops it when too long. */
  private endLine(piece: Uint8Array, frame: (values: Float64Array) => void): void {
    if (this.overflow || this.used + piece.length > this.maxLine) {
      this.stats.malformed++;
      this.stats.lastProblem = `a line longer than ${this.maxLine} bytes`;
      this.used = 0;
      this.overflow = false;
      return;
    }
    if (this.used > 0) {
      this.append(piece);
      this.decodeLine(this.pending.subarray(0, this.used), frame);
      this.used = 0;
    } else {
      this.decodeLine(piece, frame);
    }
  }

  /** Keeps the unfinished line at the end of a chunk (or notes that it is too long). */
  private carry(rest: Uint8Array): void {
    if (rest.length === 0) return;
    if (this.overflow || this.used + rest.length > this.maxLine) this.overflow = true;
    else this.append(rest);
  }

  /** Decodes one whole line (blank lines are skipped); counts it when it is malformed. */
  private decodeLine(bytes: Uint8Array, frame: (values: Float64Array) => void): void {
    const text = latin1(bytes).trim();
    if (text === "") return;
    const parts = text.split(this.sep);
    const channels = this.channels;
    if (parts.length !== channels) {
      this.stats.malformed++;
      this.stats.lastProblem = `a line with ${parts.length} value${parts.length === 1 ? "" : "s"} (expected ${channels}): "${clip(text)}"`;
      return;
    }
    if (!this.readNumbers(parts, text)) return;
    this.stats.frames++;
    frame(this.out);
  }

  /** Parses the line's `parts` into `out`; false (counted) when one is not a number. */
  private readNumbers(parts: readonly string[], text: string): boolean {
    const out = this.out;
    for (let i = 0; i < this.channels; i++) {
      const s = parts[i]!;
      const v = Number(s);
      if (s === "" || !Number.isFinite(v)) {
        this.stats.malformed++;
        this.stats.lastProblem = `"${clip(s)}" is not a number in the line "${clip(text)}"`;
        return false;
      }
      out[i] = v;
    }
    return true;
  }

  /** Appends `piece` to the carried line, growing its buffer when needed. */
  private append(piece: Uint8Array): void {
    const used = this.used;
    if (used + piece.length > this.pending.length) {
      const bigger = new Uint8Array(Math.max(this.pending.length * 2, used + piece.length));
      bigger.set(this.pending.subarray(0, used));
      this.pending = bigger;
    }
    this.pending.set(piece, used);
    this.used = used + piece.length;
  }
}

/** Writes `v1,v2,…\n` with the shortest round-trip form of each number. */
export function lineEncoder(separator = ","): Encoder {
  return {
    encode(values) {
      const parts: string[] = [];
      for (let i = 0; i < values.length; i++) parts.push(String(values[i]));
      const text = parts.join(separator) + "\n";
      const bytes = new Uint8Array(text.length);
      for (let i = 0; i < text.length; i++) bytes[i] = text.charCodeAt(i) & 0xff;
      return bytes;
    },
  };
}

/** Bytes as Latin-1 text (numbers are ASCII; anything else is kept visible in messages). */
function latin1(bytes: Uint8Array): string {
  let s = "";
  for (let i = 0; i < bytes.length; i += 1024) {
    s += String.fromCharCode(...bytes.subarray(i, Math.min(i + 1024, bytes.length)));
  }
  return s;
}

function clip(s: string): string {
  return s.length > 60 ? s.slice(0, 57) + "…" : s;
}

// ---------------------------------------------------------------------------------------------
// Binary structs

export interface StructOptions {
  /** One numeric field per channel, in order. */
  fields: readonly FieldType[];
  /** Bytes that start every frame (may be empty: then frames follow each other back to back). */
  sync: readonly number[];
  checksum: Checksum;
  littleEndian: boolean;
}

/** Size of one frame in bytes: sync + fields + checksum. */
export function structSize(o: StructOptions): number {
  return o.sync.length + payloadSize(o.fields) + CHECKSUM_SIZE[o.checksum];
}

function payloadSize(fields: readonly FieldType[]): number {
  let n = 0;
  for (const f of fields) n += FIELD_SIZE[f];
  return n;
}

/**
 * The checksum of `bytes`: xor8 (XOR of all bytes), sum8 (sum modulo 256), crc16
 * (CRC-16/CCITT-FALSE: polynomial 0x1021, initial 0xFFFF, no reflection, no final XOR).
 * It covers the payload only (not the sync bytes); crc16 is written in the frame's byte order.
 */
export function checksumOf(kind: Checksum, bytes: Uint8Array): number {
  switch (kind) {
    case "none":
      return 0;
    case "xor8": {
      let x = 0;
      for (const b of bytes) x ^= b;
      return x;
    }
    case "sum8": {
      let s = 0;
      for (const b of bytes) s = (s + b) & 0xff;
      return s;
    }
    case "crc16": {
      let crc = 0xffff;
      for (const b of bytes) {
        crc ^= b << 8;
        for (let k = 0; k < 8; k++)
          crc = crc & 0x8000 ? ((crc << 1) ^ 0x1021) & 0xffff : (crc << 1) & 0xffff;
      }
      return crc;
    }
  }
}

function readField(view: DataView, offset: number, type: FieldType, le: boolean): number {
  switch (type) {
    case "i8":
      return view.getInt8(offset);
    case "u8":
      return view.getUint8(offset);
    case "i16":
      return view.getInt16(offset, le);
    case "u16":
      return view.getUint16(offset, le);
    case "i32":
      return view.getInt32(offset, le);
    case "u32":
      return view.getUint32(offset, le);
    case "f32":
      return view.getFloat32(offset, le);
    case "f64":
      return view.getFloat64(offset, le);
  }
}

function writeField(view: DataView, offset: number, type: FieldType, v: number, le: boolean): void {
  const int = (lo: number, hi: number): number =>
    Number.isFinite(v) ? Math.min(hi, Math.max(lo, Math.round(v))) : 0;
  switch (type) {
    case "i8":
      return view.setInt8(offset, int(-128, 127));
    case "u8":
      return view.setUint8(offset, int(0, 255));
    case "i16":
      return view.setInt16(offset, int(-32768, 32767), le);
    case "u16":
      return view.setUint16(offset, int(0, 65535), le);
    case "i32":
      return view.setInt32(offset, int(-2147483648, 2147483647), le);
    case "u32":
      return view.setUint32(offset, int(0, 4294967295), le);
    case "f32":
      return view.setFloat32(offset, v, le);
    case "f64":
      return view.setFloat64(offset, v, le);
  }
}

/**
 * Fixed-size binary frames: [sync…][fields…][checksum]. On a checksum mismatch the decoder
 * drops one byte and looks for the next sync, so a corrupted or torn frame costs at most that
 * frame.
 */
export function structDecoder(o: StructOptions): Decoder {
  return new StructDecoder(o);
}

/** The struct decoder: received bytes wait in a fixed buffer until they make a whole frame. */
class StructDecoder implements Decoder {
  readonly stats = newStats();
  /** Bytes per frame: sync + payload + checksum. */
  private readonly size: number;
  /** Bytes of the fields. */
  private readonly payload: number;
  private readonly csSize: number;
  /** The vector handed to `frame` (reused). */
  private readonly out: Float64Array;
  /** Bytes received and not yet decoded: `buf[0, used)`. */
  private readonly buf: Uint8Array;
  private readonly view: DataView;
  private used = 0;

  constructor(private readonly o: StructOptions) {
    this.size = structSize(o);
    this.payload = payloadSize(o.fields);
    this.csSize = CHECKSUM_SIZE[o.checksum];
    this.out = new Float64Array(o.fields.length);
    this.buf = new Uint8Array(Math.max(this.size * 64, 1024));
    this.view = new DataView(this.buf.buffer);
  }

  reset(): void {
    this.used = 0;
  }

  push(bytes: Uint8Array, frame: (values: Float64Array) => void): void {
    const buf = this.buf;
    let offset = 0;
    while (offset < bytes.length) {
      const n = Math.min(bytes.length - offset, buf.length - this.used);
      buf.set(bytes.subarray(offset, offset + n), this.used);
      this.used += n;
      offset += n;
      const i = this.decodeFrames(frame);
      buf.copyWithin(0, i, this.used);
      this.used -= i;
    }
  }

  /** Decodes every whole frame in the buffer; returns how many bytes were used up (or skipped). */
  private decodeFrames(frame: (values: Float64Array) => void): number {
    const size = this.size;
    const stats = this.stats;
    let i = 0;
    while (this.used - i >= size) {
      if (!this.syncAt(i)) {
        i++;
        stats.skipped++;
        continue;
      }
      const p = i + this.o.sync.length;
      if (!this.checksumMatches(p)) {
        i++;
        continue;
      }
      this.readFields(p);
      stats.frames++;
      frame(this.out);
      i += size;
    }
    return i;
  }

  /** Whether the sync bytes are at `buf[i]`. */
  private syncAt(i: number): boolean {
    const sync = this.o.sync;
    for (let k = 0; k < sync.length; k++) if (this.buf[i + k] !== sync[k]) return false;
    return true;
  }

  /** Whether the payload at `p` matches the checksum after it (or there is none); counts a miss. */
  private checksumMatches(p: number): boolean {
    const { o, buf, payload, csSize } = this;
    if (csSize === 0) return true;
    const want = checksumOf(o.checksum, buf.subarray(p, p + payload));
    const got = csSize === 1 ? buf[p + payload]! : this.view.getUint16(p + payload, o.littleEndian);
    if (want === got) return true;
    this.stats.malformed++;
    this.stats.lastProblem = `a frame with a bad ${o.checksum} checksum (0x${got.toString(16)}, computed 0x${want.toString(16)})`;
    return false;
  }

  /** Reads the fields of the payload at `p` into `out`. */
  private readFields(p: number): void {
    const { o, view, out } = this;
    let q = p;
    for (let f = 0; f < o.fields.length; f++) {
      out[f] = readField(view, q, o.fields[f]!, o.littleEndian);
      q += FIELD_SIZE[o.fields[f]!];
    }
  }
}

/** Writes one frame per vector (integers rounded and clamped to their type's range). */
export function structEncoder(o: StructOptions): Encoder {
  const size = structSize(o);
  const payload = payloadSize(o.fields);
  return {
    encode(values) {
      const bytes = new Uint8Array(size);
      const view = new DataView(bytes.buffer);
      bytes.set(o.sync, 0);
      let q = o.sync.length;
      for (let f = 0; f < o.fields.length; f++) {
        writeField(view, q, o.fields[f]!, values[f] ?? 0, o.littleEndian);
        q += FIELD_SIZE[o.fields[f]!];
      }
      const p = o.sync.length;
      const cs = checksumOf(o.checksum, bytes.subarray(p, p + payload));
      if (CHECKSUM_SIZE[o.checksum] === 1) bytes[q] = cs;
      else if (CHECKSUM_SIZE[o.checksum] === 2) view.setUint16(q, cs, o.littleEndian);
      return bytes;
    },
  };
}
