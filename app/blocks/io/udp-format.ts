/**
 * The UDP wire formats (docs/protocols.md): MOSAIC's "streamlined" datagram, as its
 * UDP_StreamlinedSender wrote it, and raw little-endian vectors (f32 or f64).
 *
 * Streamlined datagram (all multi-byte fields little-endian):
 *
 * | offset      | size      | field                                                    |
 * | ----------- | --------- | -------------------------------------------------------- |
 * | 0           | 1         | count: number of values (not bytes), 0–255               |
 * | 1           | 1         | type byte: 0x20 float flag + 0x10 signed flag + size     |
 * | 2           | 1         | category                                                 |
 * | 3           | 1         | subcategory                                              |
 * | 4           | 8         | timestamp: f64, UNIX seconds                             |
 * | 12          | count·size| values                                                   |
 * | 12+count·size | 2       | counter: u16, +1 per datagram the sender sent, wraps 65535 → 0 |
 *
 * Encoding and decoding never allocate per datagram: the encoder writes into one buffer that it
 * reuses (the bridge copies it when it sends), the decoder writes values into a caller's array.
 */

export type ValueType = "f64" | "f32" | "i8" | "i16" | "i32" | "i64" | "u8" | "u16" | "u32" | "u64";

export const HEADER_BYTES = 12;
export const COUNTER_BYTES = 2;
/** Streamlined: count is one byte. */
export const MAX_STREAMLINED_VALUES = 255;
/** Largest UDP payload over IPv4. */
export const MAX_DATAGRAM_BYTES = 65_507;

export const FLOAT_FLAG = 0x20;
export const SIGNED_FLAG = 0x10;

interface TypeInfo {
  size: number;
  float: boolean;
  signed: boolean;
  min: number;
  max: number;
}

const TYPES: Record<ValueType, TypeInfo> = {
  f64: { size: 8, float: true, signed: true, min: -Infinity, max: Infinity },
  f32: { size: 4, float: true, signed: true, min: -Infinity, max: Infinity },
  i8: { size: 1, float: false, signed: true, min: -128, max: 127 },
  i16: { size: 2, float: false, signed: true, min: -32768, max: 32767 },
  i32: { size: 4, float: false, signed: true, min: -2147483648, max: 2147483647 },
  i64: { size: 8, float: false, signed: true, min: -(2 ** 63), max: 2 ** 63 - 1 },
  u8: { size: 1, float: false, signed: false, min: 0, max: 255 },
  u16: { size: 2, float: false, signed: false, min: 0, max: 65535 },
  u32: { size: 4, float: false, signed: false, min: 0, max: 4294967295 },
  u64: { size: 8, float: false, signed: false, min: 0, max: 2 ** 64 - 1 },
};

export const VALUE_TYPES = Object.keys(TYPES) as ValueType[];

export function valueSize(t: ValueType): number {
  return TYPES[t].size;
}

/** The type byte of MOSAIC's protocol: f64 0x28, f32 0x24, i8 0x11, i16 0x12, i32 0x14, u8 0x01, … */
export function typeByte(t: ValueType): number {
  const i = TYPES[t];
  return (i.float ? FLOAT_FLAG : i.signed ? SIGNED_FLAG : 0) + i.size;
}

/** The value type a type byte stands for, or undefined when no type has that byte. */
export function typeFromByte(b: number): ValueType | undefined {
  for (const t of VALUE_TYPES) if (typeByte(t) === b) return t;
  return undefined;
}

/** Bytes of a streamlined datagram holding `count` values of type `t`. */
export function streamlinedLength(count: number, t: ValueType): number {
  return HEADER_BYTES + count * valueSize(t) + COUNTER_BYTES;
}

/**
 * Writes `x` as type `t` at `off`. Integers are rounded to nearest and saturated at the type's
 * range (NaN becomes 0): MOSAIC's cast wrapped around, so 1.0 · 128 became −128 in its Myo
 * serializer; saturating sends 127 instead.
 */
function writeValue(dv: DataView, off: number, t: ValueType, x: number): void {
  switch (t) {
    case "f64":
      dv.setFloat64(off, x, true);
      return;
    case "f32":
      dv.setFloat32(off, x, true);
      return;
    default: {
      const info = TYPES[t];
      let v = x !== x ? 0 : Math.round(x);
      if (v < info.min) v = info.min;
      else if (v > info.max) v = info.max;
      switch (t) {
        case "i8":
          dv.setInt8(off, v);
          return;
        case "u8":
          dv.setUint8(off, v);
          return;
        case "i16":
          dv.setInt16(off, v, true);
          return;
        case "u16":
          dv.setUint16(off, v, true);
          return;
        case "i32":
          dv.setInt32(off, v, true);
          return;
        case "u32":
          dv.setUint32(off, v, true);
          return;
        case "i64":
          dv.setBigInt64(off, v >= info.max ? 2n ** 63n - 1n : BigInt(v), true);
          return;
        case "u64":
          dv.setBigUint64(off, v >= info.max ? 2n ** 64n - 1n : BigInt(v), true);
          return;
      }
    }
  }
}

function readValue(dv: DataView, off: number, t: ValueType): number {
  switch (t) {
    case "f64":
      return dv.getFloat64(off, true);
    case "f32":
      return dv.getFloat32(off, true);
    case "i8":
      return dv.getInt8(off);
    case "u8":
      return dv.getUint8(off);
    case "i16":
      return dv.getInt16(off, true);
    case "u16":
      return dv.getUint16(off, true);
    case "i32":
      return dv.getInt32(off, true);
    case "u32":
      return dv.getUint32(off, true);
    case "i64":
      return Number(dv.getBigInt64(off, true));
    case "u64":
      return Number(dv.getBigUint64(off, true));
  }
}

/** Encodes streamlined datagrams of a fixed count and type into one reused buffer. */
export class StreamlinedEncoder {
  readonly bytes: Uint8Array;
  private readonly dv: DataView;
  private readonly size: number;
  /** Counter of the next datagram (u16). */
  counter = 0;

  constructor(
    readonly count: number,
    readonly type: ValueType,
  ) {
    if (!(Number.isInteger(count) && count >= 0 && count <= MAX_STREAMLINED_VALUES)) {
      throw new RangeError(`a streamlined datagram holds 0 to 255 values, not ${count}`);
    }
    this.size = valueSize(type);
    this.bytes = new Uint8Array(streamlinedLength(count, type));
    this.dv = new DataView(this.bytes.buffer);
    this.bytes[0] = count;
    this.bytes[1] = typeByte(type);
  }

  /**
   * Writes one datagram: `count` values from `src` starting at `offset`, each multiplied by
   * `scale`; bumps the counter. Returns the datagram (valid until the next call).
   */
  encode(
    timestamp: number,
    category: number,
    subcategory: number,
    src: ArrayLike<number>,
    offset: number,
    scale = 1,
  ): Uint8Array {
    const dv = this.dv;
    this.bytes[2] = category;
    this.bytes[3] = subcategory;
    dv.setFloat64(4, timestamp, true);
    let off = HEADER_BYTES;
    for (let i = 0; i < this.count; i++, off += this.size) {
      writeValue(dv, off, this.type, src[offset + i]! * scale);
    }
    dv.setUint16(off, this.counter, true);
    this.counter = (this.counter + 1) & 0xffff;
    return this.bytes;
  }
}

/** Encodes raw little-endian vectors (no header): `count` values of f32 or f64. */
export class RawEncoder {
  readonly bytes: Uint8Array;
  private readonly dv: DataView;

  constructor(
    readonly count: number,
    readonly type: "f32" | "f64",
  ) {
    this.bytes = new Uint8Array(count * valueSize(type));
    this.dv = new DataView(this.bytes.buffer);
  }

  encode(src: ArrayLike<number>, offset: number, scale = 1): Uint8Array {
    const dv = this.dv;
    if (this.type === "f64") {
      for (let i = 0; i < this.count; i++) dv.setFloat64(8 * i, src[offset + i]! * scale, true);
    } else {
      for (let i = 0; i < this.count; i++) dv.setFloat32(4 * i, src[offset + i]! * scale, true);
    }
    return this.bytes;
  }
}

/** A decoded streamlined header (values are written to the caller's array). */
export interface StreamlinedHeader {
  count: number;
  type: ValueType;
  category: number;
  subcategory: number;
  timestamp: number;
  counter: number;
}

export const newHeader = (): StreamlinedHeader => ({
  count: 0,
  type: "f64",
  category: 0,
  subcategory: 0,
  timestamp: 0,
  counter: 0,
});

const hex = (b: number): string => `0x${b.toString(16).padStart(2, "0")}`;

/**
 * Decodes one streamlined datagram into `header`; its values go to `out` from `outOffset` (which
 * must have room for `maxValues`). Never throws: returns why a malformed datagram was refused, or
 * undefined.
 */
export function decodeStreamlined(
  data: Uint8Array,
  header: StreamlinedHeader,
  out: Float64Array,
  outOffset: number,
  maxValues: number,
  scale = 1,
): string | undefined {
  const len = data.length;
  if (len < HEADER_BYTES + COUNTER_BYTES) {
    return `${len} bytes is shorter than the ${HEADER_BYTES + COUNTER_BYTES}-byte header and counter`;
  }
  const count = data[0]!;
  const tb = data[1]!;
  const type = typeFromByte(tb);
  if (type === undefined) {
    return (
      `unknown type byte ${hex(tb)} (expected 0x20 float / 0x10 signed / 0x00 unsigned + size ` +
      `in bytes: 0x28 f64, 0x24 f32, 0x11 i8, 0x12 i16, 0x14 i32, 0x18 i64, 0x01 u8, 0x02 u16, 0x04 u32, 0x08 u64)`
    );
  }
  const expected = streamlinedLength(count, type);
  if (len !== expected) {
    return `${count} values of ${type} need ${expected} bytes, got ${len}`;
  }
  if (count > maxValues) {
    return `${count} values, more than the ${maxValues} expected`;
  }
  const dv = new DataView(data.buffer, data.byteOffset, len);
  const size = valueSize(type);
  let off = HEADER_BYTES;
  for (let i = 0; i < count; i++, off += size)
    out[outOffset + i] = readValue(dv, off, type) * scale;
  header.count = count;
  header.type = type;
  header.category = data[2]!;
  header.subcategory = data[3]!;
  header.timestamp = dv.getFloat64(4, true);
  header.counter = dv.getUint16(off, true);
  return undefined;
}

/**
 * Decodes a raw datagram of k whole vectors of `channels` values (f32 or f64); returns k, or why
 * it was refused. Values go to `out` from 0 (room for `maxVectors` vectors).
 */
export function decodeRaw(
  data: Uint8Array,
  type: "f32" | "f64",
  channels: number,
  out: Float64Array,
  maxVectors: number,
  scale = 1,
): number | string {
  const size = valueSize(type);
  const vecBytes = channels * size;
  const len = data.length;
  if (len === 0 || len % vecBytes !== 0) {
    return `${len} bytes is not a whole number of ${channels}-value ${type} vectors (${vecBytes} bytes each)`;
  }
  const k = len / vecBytes;
  if (k > maxVectors) {
    return `${k} vectors in one datagram, more than ${maxVectors}`;
  }
  const dv = new DataView(data.buffer, data.byteOffset, len);
  const n = k * channels;
  if (type === "f64") {
    for (let i = 0; i < n; i++) out[i] = dv.getFloat64(8 * i, true) * scale;
  } else {
    for (let i = 0; i < n; i++) out[i] = dv.getFloat32(4 * i, true) * scale;
  }
  return k;
}

/** Datagrams lost between two counters (u16, wrapping); negative when `counter` came early (reordered). */
export function counterGap(previous: number, counter: number): number {
  const d = (counter - previous - 1) & 0xffff;
  // More than half the range ahead: a late (reordered or repeated) datagram, not 40,000 lost.
  return d >= 0x8000 ? d - 0x10000 : d;
}
