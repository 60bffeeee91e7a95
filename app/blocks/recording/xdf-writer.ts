/**
 * XDF 1.0 writing, as LabRecorder writes it (https://github.com/sccn/xdf/wiki/Specifications):
 * the magic `XDF:`, then chunks `[NumLengthBytes][Length][Tag][Content]`, where NumLengthBytes
 * (1, 4 or 8) says how many bytes the little-endian Length takes and Length counts the Tag (uint16)
 * and the Content. Tags: 1 FileHeader (XML), 2 StreamHeader (StreamId uint32 + XML), 3 Samples
 * (StreamId, a variable-length NumSamples, then per sample a TimeStampBytes byte (8 here, always),
 * the float64 timestamp and the values: little-endian numbers, or per string channel a
 * variable-length byte count and the UTF-8 bytes), 4 ClockOffset (StreamId, CollectionTime f64,
 * OffsetValue f64), 5 Boundary (a fixed 16-byte UUID, so a reader can find its place again in a
 * damaged file) and 6 StreamFooter (StreamId + XML).
 *
 * Samples are serialised as they arrive (`NumericStream.append` copies a frame into a byte buffer
 * with a DataView; no object per sample) and go out as one Samples chunk per stream per flush.
 */

export const XDF_MAGIC = Uint8Array.of(0x58, 0x44, 0x46, 0x3a); // "XDF:"

export const TAG_FILE_HEADER = 1;
export const TAG_STREAM_HEADER = 2;
export const TAG_SAMPLES = 3;
export const TAG_CLOCK_OFFSET = 4;
export const TAG_BOUNDARY = 5;
export const TAG_STREAM_FOOTER = 6;

/** The Boundary chunk's content, fixed by the specification. */
export const BOUNDARY_UUID = Uint8Array.of(
  0x43,
  0xa5,
  0x46,
  0xdc,
  0xcb,
  0xf5,
  0x41,
  0x0f,
  0xb3,
  0x0e,
  0xd5,
  0x46,
  0x73,
  0x83,
  0xcb,
  0xe4,
);

export type NumericFormat = "float32" | "double64";
export type ChannelFormat = NumericFormat | "string";

/** Bytes one value of a numeric format takes. */
export const formatBytes = (f: NumericFormat): number => (f === "float32" ? 4 : 8);

/** Bytes a variable-length integer takes: its NumLengthBytes byte and 1, 4 or 8 bytes. */
export function varLenSize(n: number): number {
  if (n < 0x100) return 2;
  if (n < 0x1_0000_0000) return 5;
  return 9;
}

/** Writes `n` as a variable-length integer at `pos`; returns the position after it. */
export function putVarLen(dv: DataView, pos: number, n: number): number {
  if (!(Number.isInteger(n) && n >= 0 && n <= Number.MAX_SAFE_INTEGER)) {
    throw new Error(`an XDF length must be a whole number of bytes, got ${n}`);
  }
  if (n < 0x100) {
    dv.setUint8(pos, 1);
    dv.setUint8(pos + 1, n);
    return pos + 2;
  }
  if (n < 0x1_0000_0000) {
    dv.setUint8(pos, 4);
    dv.setUint32(pos + 1, n, true);
    return pos + 5;
  }
  dv.setUint8(pos, 8);
  dv.setBigUint64(pos + 1, BigInt(n), true);
  return pos + 9;
}

/** A growable byte buffer (allocates only when more is needed than ever before). */
export class ByteBuffer {
  bytes: Uint8Array;
  view: DataView;
  length = 0;

  constructor(capacity = 4096) {
    this.bytes = new Uint8Array(Math.max(16, capacity));
    this.view = new DataView(this.bytes.buffer);
  }

  /** Makes room for `extra` more bytes. */
  reserve(extra: number): void {
    const need = this.length + extra;
    if (need <= this.bytes.length) return;
    let cap = this.bytes.length;
    while (cap < need) cap *= 2;
    const b = new Uint8Array(cap);
    b.set(this.bytes.subarray(0, this.length));
    this.bytes = b;
    this.view = new DataView(b.buffer);
  }

  put(src: Uint8Array): void {
    this.reserve(src.length);
    this.bytes.set(src, this.length);
    this.length += src.length;
  }

  /** The bytes written so far (a view; valid until the next write). */
  get used(): Uint8Array {
    return this.bytes.subarray(0, this.length);
  }

  clear(): void {
    this.length = 0;
  }
}

/** UTF-8 encoding: TextEncoder exists wherever the engine runs (Node, browsers, workers). */
const utf8 = new (
  globalThis as unknown as { TextEncoder: new () => { encode(s: string): Uint8Array } }
).TextEncoder();

/**
 * Appends a chunk's `[NumLengthBytes][Length][Tag]` (and the StreamId for stream chunks) for a
 * content of `contentBytes` bytes after them; the caller writes the content.
 */
export function putChunkHead(
  out: ByteBuffer,
  tag: number,
  streamId: number | null,
  contentBytes: number,
): void {
  const length = 2 + (streamId === null ? 0 : 4) + contentBytes;
  out.reserve(9 + length);
  let p = putVarLen(out.view, out.length, length);
  out.view.setUint16(p, tag, true);
  p += 2;
  if (streamId !== null) {
    out.view.setUint32(p, streamId, true);
    p += 4;
  }
  out.length = p;
}

/** Appends a chunk whose content is XML (FileHeader, StreamHeader, StreamFooter). */
export function putXmlChunk(out: ByteBuffer, tag: number, streamId: number | null, xml: string) {
  const bytes = utf8.encode(xml);
  putChunkHead(out, tag, streamId, bytes.length);
  out.put(bytes);
}

export function putClockOffset(out: ByteBuffer, streamId: number, time: number, value: number) {
  putChunkHead(out, TAG_CLOCK_OFFSET, streamId, 16);
  out.view.setFloat64(out.length, time, true);
  out.view.setFloat64(out.length + 8, value, true);
  out.length += 16;
}

export function putBoundary(out: ByteBuffer): void {
  putChunkHead(out, TAG_BOUNDARY, null, BOUNDARY_UUID.length);
  out.put(BOUNDARY_UUID);
}

// ---------------------------------------------------------------------------------------------
// XML

const XML_ESCAPES: Record<string, string> = {
  "&": "&amp;",
  "<": "&lt;",
  ">": "&gt;",
  '"': "&quot;",
  "'": "&apos;",
};
/** Text for an XML element; characters XML 1.0 cannot hold (controls) are dropped. */
export function xmlText(s: string): string {
  return s
    .replace(/[\u0000-\u0008\u000b\u000c\u000e-\u001f\ufffe\uffff]/g, "")
    .replace(/[&<>"']/g, (c) => XML_ESCAPES[c]!);
}

/** A number in XML: shortest round-trip form. */
const num = (x: number): string => String(x);

export function fileHeaderXml(datetime: string): string {
  return (
    '<?xml version="1.0"?>\n<info>\n\t<version>1.0</version>\n' +
    `\t<datetime>${xmlText(datetime)}</datetime>\n\t<writer>MOSAIC XdfRecorder</writer>\n</info>`
  );
}

/** What a StreamHeader says (the fields of an LSL stream info, as LabRecorder stores them). */
export interface StreamInfo {
  name: string;
  type: string;
  channelCount: number;
  /** Hz; 0 for an irregular stream (markers). */
  nominalRate: number;
  format: ChannelFormat;
  sourceId: string;
  /** One label per channel. */
  labels: readonly string[];
  /** Unit of every channel (omitted when empty). */
  unit: string;
  /** Clock time the stream was created, s. */
  createdAt: number;
  uid: string;
  hostname: string;
}

export function streamHeaderXml(s: StreamInfo): string {
  const channels: string[] = [];
  for (const label of s.labels) {
    channels.push(
      `\t\t\t<channel>\n\t\t\t\t<label>${xmlText(label)}</label>\n` +
        (s.unit !== "" ? `\t\t\t\t<unit>${xmlText(s.unit)}</unit>\n` : "") +
        `\t\t\t\t<type>${xmlText(s.type)}</type>\n\t\t\t</channel>\n`,
    );
  }
  return (
    '<?xml version="1.0"?>\n<info>\n' +
    `\t<name>${xmlText(s.name)}</name>\n` +
    `\t<type>${xmlText(s.type)}</type>\n` +
    `\t<channel_count>${s.channelCount}</channel_count>\n` +
    `\t<channel_format>${s.format}</channel_format>\n` +
    `\t<source_id>${xmlText(s.sourceId)}</source_id>\n` +
    `\t<nominal_srate>${num(s.nominalRate)}</nominal_srate>\n` +
    "\t<version>1.1000000000000001</version>\n" +
    `\t<created_at>${num(s.createdAt)}</created_at>\n` +
    `\t<uid>${xmlText(s.uid)}</uid>\n` +
    "\t<session_id>default</session_id>\n" +
    `\t<hostname>${xmlText(s.hostname)}</hostname>\n` +
    "\t<desc>\n\t\t<channels>\n" +
    channels.join("") +
    "\t\t</channels>\n\t\t<acquisition>\n\t\t\t<manufacturer>MOSAIC</manufacturer>\n" +
    "\t\t</acquisition>\n\t</desc>\n</info>"
  );
}

/** What a StreamFooter says. */
export interface StreamSummary {
  firstTimestamp: number;
  lastTimestamp: number;
  sampleCount: number;
  /** Clock offsets as (collection time, offset value) pairs. */
  clockOffsets: readonly (readonly [number, number])[];
}

export function streamFooterXml(s: StreamSummary): string {
  const offsets = s.clockOffsets
    .map(
      ([t, v]) =>
        `\t\t<offset>\n\t\t\t<time>${num(t)}</time>\n\t\t\t<value>${num(v)}</value>\n\t\t</offset>\n`,
    )
    .join("");
  return (
    '<?xml version="1.0"?>\n<info>\n' +
    `\t<first_timestamp>${num(s.firstTimestamp)}</first_timestamp>\n` +
    `\t<last_timestamp>${num(s.lastTimestamp)}</last_timestamp>\n` +
    `\t<sample_count>${s.sampleCount}</sample_count>\n` +
    `\t<clock_offsets>\n${offsets}\t</clock_offsets>\n</info>`
  );
}

// ---------------------------------------------------------------------------------------------
// Streams: samples serialised as they arrive, one Samples chunk per flush

/** Samples of one stream waiting for the next flush, already in their file form. */
export abstract class PendingStream {
  /** Samples waiting. */
  pending = 0;
  /** Samples written to chunks since the stream began. */
  written = 0;
  firstTimestamp = NaN;
  lastTimestamp = NaN;
  readonly clockOffsets: [number, number][] = [];
  protected readonly buf: ByteBuffer;

  constructor(
    readonly id: number,
    initialBytes: number,
  ) {
    this.buf = new ByteBuffer(initialBytes);
  }

  /** Bytes waiting. */
  get pendingBytes(): number {
    return this.buf.length;
  }

  protected stamp(t: number): void {
    if (Number.isNaN(this.firstTimestamp)) this.firstTimestamp = t;
    this.lastTimestamp = t;
  }

  /** Moves the waiting samples into `out` as one Samples chunk (nothing when none wait). */
  takeChunk(out: ByteBuffer): void {
    if (this.pending === 0) return;
    const n = this.pending;
    putChunkHead(out, TAG_SAMPLES, this.id, varLenSize(n) + this.buf.length);
    out.length = putVarLen(out.view, out.length, n);
    out.put(this.buf.used);
    this.buf.clear();
    this.written += n;
    this.pending = 0;
  }

  summary(): StreamSummary {
    const none = this.written === 0;
    return {
      firstTimestamp: none ? 0 : this.firstTimestamp,
      lastTimestamp: none ? 0 : this.lastTimestamp,
      sampleCount: this.written,
      clockOffsets: this.clockOffsets,
    };
  }
}

/** A numeric stream (float32 or double64): each sample is 1 + 8 + channels × 4|8 bytes. */
export class NumericStream extends PendingStream {
  readonly sampleBytes: number;
  private readonly double: boolean;

  constructor(
    id: number,
    readonly channels: number,
    format: NumericFormat,
    expectedSamples = 256,
  ) {
    const sampleBytes = 9 + channels * formatBytes(format);
    super(id, sampleBytes * Math.max(1, expectedSamples));
    this.sampleBytes = sampleBytes;
    this.double = format === "double64";
  }

  /**
   * Appends events `[0, n)`: timestamps `t[i]`, values `v[i*stride + k]` for k < channels (a
   * frame's arrays). Copies; nothing of `t` or `v` is kept.
   */
  append(t: Float64Array, v: Float64Array, n: number, stride: number): void {
    if (n <= 0) return;
    const C = this.channels;
    const b = this.buf;
    b.reserve(n * this.sampleBytes);
    const dv = b.view;
    let p = b.length;
    for (let i = 0; i < n; i++) {
      dv.setUint8(p, 8);
      dv.setFloat64(p + 1, t[i]!, true);
      p += 9;
      const base = i * stride;
      if (this.double) {
        for (let k = 0; k < C; k++, p += 8) dv.setFloat64(p, v[base + k]!, true);
      } else {
        for (let k = 0; k < C; k++, p += 4) dv.setFloat32(p, v[base + k]!, true);
      }
    }
    b.length = p;
    this.pending += n;
    this.stamp(t[0]!);
    this.lastTimestamp = t[n - 1]!;
  }
}

/** A string stream of one channel (markers): each sample is 1 + 8 + a length + UTF-8 bytes. */
export class MarkerStream extends PendingStream {
  constructor(id: number) {
    super(id, 1024);
  }

  append(t: number, text: string): void {
    const bytes = utf8.encode(text);
    const b = this.buf;
    b.reserve(9 + 9 + bytes.length);
    b.view.setUint8(b.length, 8);
    b.view.setFloat64(b.length + 1, t, true);
    b.length = putVarLen(b.view, b.length + 9, bytes.length);
    b.put(bytes);
    this.pending++;
    this.stamp(t);
  }
}
