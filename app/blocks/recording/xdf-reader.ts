/**
 * XDF 1.0 reading (https://github.com/sccn/xdf/wiki/Specifications), for `mosaic repair`, the
 * tests and a FilePlayer: chunks are read one at a time from a random-access source (a
 * `FileReadHandle`), so a file of any size is scanned without holding it in memory. A file that
 * ends inside a chunk (a recording killed while writing) ends the scan at the last whole chunk,
 * and `problem` says why; nothing is thrown for it.
 */
import {
  TAG_BOUNDARY,
  TAG_CLOCK_OFFSET,
  TAG_FILE_HEADER,
  TAG_SAMPLES,
  TAG_STREAM_FOOTER,
  TAG_STREAM_HEADER,
  XDF_MAGIC,
} from "./xdf-writer";

/** What a reader needs of a file: its size and reads at a position (a `FileReadHandle`). */
export interface ByteSource {
  readonly size: number;
  read(into: Uint8Array, position: number): number;
}

/** An in-memory file (tests, small files). */
export function bytesSource(bytes: Uint8Array): ByteSource {
  return {
    size: bytes.length,
    read(into, position) {
      const n = Math.max(0, Math.min(into.length, bytes.length - position));
      into.set(bytes.subarray(position, position + n));
      return n;
    },
  };
}

export interface XdfChunk {
  /** Byte offset of the chunk's NumLengthBytes byte. */
  offset: number;
  tag: number;
  /** For StreamHeader, Samples, ClockOffset and StreamFooter chunks; null otherwise. */
  streamId: number | null;
  /** Byte offset and length of the content after the tag (and the StreamId). */
  contentOffset: number;
  contentLength: number;
  /** Byte offset just after the chunk. */
  end: number;
}

const STREAM_TAGS = new Set([TAG_STREAM_HEADER, TAG_SAMPLES, TAG_CLOCK_OFFSET, TAG_STREAM_FOOTER]);
const KNOWN_TAGS = new Set([
  TAG_FILE_HEADER,
  TAG_STREAM_HEADER,
  TAG_SAMPLES,
  TAG_CLOCK_OFFSET,
  TAG_BOUNDARY,
  TAG_STREAM_FOOTER,
]);

/** Reads the chunks of an XDF file in order. */
export class XdfChunkReader {
  /** Why the scan stopped before the end of the file (a torn or damaged chunk); "" otherwise. */
  problem = "";
  /** Byte offset after the last whole chunk read so far. */
  validEnd = 4;
  private pos = 4;
  private readonly head = new Uint8Array(15);
  private readonly headView = new DataView(this.head.buffer);
  private scratch = new Uint8Array(1 << 16);

  constructor(private readonly src: ByteSource) {
    const magic = new Uint8Array(4);
    const n = src.size >= 4 ? src.read(magic, 0) : 0;
    if (n < 4 || magic.some((b, i) => b !== XDF_MAGIC[i])) {
      throw new Error("not an XDF file: it does not start with 'XDF:'");
    }
  }

  /** The next whole chunk, or null at the end of the file or at a torn or damaged chunk. */
  next(): XdfChunk | null {
    const size = this.src.size;
    if (this.pos >= size) return null;
    const got = this.src.read(this.head, this.pos);
    const lenBytes = this.head[0]!;
    if (lenBytes !== 1 && lenBytes !== 4 && lenBytes !== 8) {
      return this.stop(`byte ${this.pos}: a chunk length of ${lenBytes} bytes (XDF has 1, 4 or 8)`);
    }
    if (got < 1 + lenBytes + 2) {
      return this.stop(`byte ${this.pos}: the file ends inside a chunk's head`);
    }
    const length =
      lenBytes === 1
        ? this.head[1]!
        : lenBytes === 4
          ? this.headView.getUint32(1, true)
          : Number(this.headView.getBigUint64(1, true));
    const tag = this.headView.getUint16(1 + lenBytes, true);
    const end = this.pos + 1 + lenBytes + length;
    if (!KNOWN_TAGS.has(tag)) {
      return this.stop(`byte ${this.pos}: unknown chunk tag ${tag}`);
    }
    const withId = STREAM_TAGS.has(tag);
    const headLength = 2 + (withId ? 4 : 0);
    if (length < headLength) {
      return this.stop(`byte ${this.pos}: a chunk of ${length} bytes is too short for tag ${tag}`);
    }
    if (end > size) {
      return this.stop(
        `byte ${this.pos}: the file ends inside a chunk (tag ${tag}, ${end - size} of its bytes missing)`,
      );
    }
    const streamId = withId ? this.headView.getUint32(3 + lenBytes, true) : null;
    const chunk: XdfChunk = {
      offset: this.pos,
      tag,
      streamId,
      contentOffset: this.pos + 1 + lenBytes + headLength,
      contentLength: length - headLength,
      end,
    };
    this.pos = end;
    this.validEnd = end;
    return chunk;
  }

  /** A chunk's content (a view into a buffer reused by the next call). */
  content(c: XdfChunk): Uint8Array {
    if (this.scratch.length < c.contentLength) {
      let cap = this.scratch.length;
      while (cap < c.contentLength) cap *= 2;
      this.scratch = new Uint8Array(cap);
    }
    const view = this.scratch.subarray(0, c.contentLength);
    let done = 0;
    while (done < view.length) {
      const n = this.src.read(view.subarray(done), c.contentOffset + done);
      if (n <= 0) throw new Error(`byte ${c.contentOffset + done}: the file ended early`);
      done += n;
    }
    return view;
  }

  /** Marks the chunk just read as damaged: the scan ends before it. */
  reject(c: XdfChunk, why: string): void {
    this.validEnd = c.offset;
    this.pos = this.src.size;
    this.problem = `byte ${c.offset}: ${why}`;
  }

  private stop(why: string): null {
    this.problem = why;
    this.pos = this.src.size;
    return null;
  }
}

// ---------------------------------------------------------------------------------------------
// XML (the few fields a reader needs; LabRecorder's XML has no attributes)

const ENTITIES: Record<string, string> = {
  amp: "&",
  lt: "<",
  gt: ">",
  quot: '"',
  apos: "'",
};
function unescapeXml(s: string): string {
  return s.replace(/&(#x[0-9a-f]+|#\d+|\w+);/gi, (m, e: string) => {
    if (e[0] === "#") {
      const code = e[1] === "x" || e[1] === "X" ? parseInt(e.slice(2), 16) : parseInt(e.slice(1));
      return Number.isFinite(code) ? String.fromCodePoint(code) : m;
    }
    return ENTITIES[e] ?? m;
  });
}

/** The text of the first `<name>…</name>` in `xml`, or undefined. */
export function xmlField(xml: string, name: string): string | undefined {
  const m = new RegExp(`<${name}>([^<]*)</${name}>`).exec(xml);
  return m ? unescapeXml(m[1]!) : undefined;
}

/** UTF-8 decoding: TextDecoder exists wherever the engine runs (Node, browsers, workers). */
export const utf8Decoder = new (
  globalThis as unknown as { TextDecoder: new () => { decode(b: Uint8Array): string } }
).TextDecoder();
const decoder = utf8Decoder;

export interface XdfStreamHeader {
  id: number;
  name: string;
  type: string;
  channelCount: number;
  nominalRate: number;
  format: string;
  sourceId: string;
  /** Channel labels from desc/channels/channel/label (empty when the header has none). */
  labels: string[];
  xml: string;
}

const VALUE_BYTES: Record<string, number> = {
  int8: 1,
  int16: 2,
  int32: 4,
  int64: 8,
  float32: 4,
  double64: 8,
};

export function parseStreamHeader(id: number, xml: string): XdfStreamHeader {
  const count = Number(xmlField(xml, "channel_count"));
  const format = xmlField(xml, "channel_format") ?? "";
  if (!(Number.isInteger(count) && count >= 0)) {
    throw new Error(`stream ${id}: its header has no valid channel_count`);
  }
  if (format !== "string" && VALUE_BYTES[format] === undefined) {
    throw new Error(`stream ${id}: unknown channel_format '${format}'`);
  }
  const labels: string[] = [];
  const channels = /<channels>([\s\S]*?)<\/channels>/.exec(xml)?.[1] ?? "";
  for (const m of channels.matchAll(/<channel>([\s\S]*?)<\/channel>/g)) {
    labels.push(xmlField(m[1]!, "label") ?? "");
  }
  return {
    id,
    name: xmlField(xml, "name") ?? "",
    type: xmlField(xml, "type") ?? "",
    channelCount: count,
    nominalRate: Number(xmlField(xml, "nominal_srate") ?? 0) || 0,
    format,
    sourceId: xmlField(xml, "source_id") ?? "",
    labels,
    xml,
  };
}

/** The samples of one Samples chunk. */
export interface XdfSamples {
  n: number;
  t: Float64Array;
  /** Numeric streams: n × channelCount values, row-major. */
  values: Float64Array | null;
  /** String streams: n × channelCount strings, row-major. */
  strings: string[] | null;
}

/** Per-stream decoding state: a sample without its own timestamp follows the previous one. */
export interface SampleClock {
  lastTimestamp: number;
}

function readVarLen(dv: DataView, p: number): [number, number] {
  const k = dv.getUint8(p);
  if (k === 1) return [dv.getUint8(p + 1), p + 2];
  if (k === 4) return [dv.getUint32(p + 1, true), p + 5];
  if (k === 8) return [Number(dv.getBigUint64(p + 1, true)), p + 9];
  throw new Error(`a variable-length integer of ${k} bytes (XDF has 1, 4 or 8)`);
}

function readValue(dv: DataView, p: number, format: string): number {
  switch (format) {
    case "float32":
      return dv.getFloat32(p, true);
    case "double64":
      return dv.getFloat64(p, true);
    case "int8":
      return dv.getInt8(p);
    case "int16":
      return dv.getInt16(p, true);
    case "int32":
      return dv.getInt32(p, true);
    default:
      return Number(dv.getBigInt64(p, true));
  }
}

/**
 * Decodes a Samples chunk's content (after the StreamId). With `values: false` only the
 * timestamps are read (a repair needs no more). Throws when the content does not hold exactly
 * the samples it announces.
 */
export function decodeSamples(
  content: Uint8Array,
  h: XdfStreamHeader,
  clock: SampleClock,
  values = true,
): XdfSamples {
  const dv = new DataView(content.buffer, content.byteOffset, content.byteLength);
  const [n, start] = readVarLen(dv, 0);
  const C = h.channelCount;
  const str = h.format === "string";
  const w = str ? 0 : VALUE_BYTES[h.format]!;
  // Each sample takes at least one byte: a count beyond the content is damage, not a big buffer.
  if (n > content.length) throw new Error(`${n} samples announced in ${content.length} bytes`);
  const t = new Float64Array(n);
  const vals = values && !str ? new Float64Array(n * C) : null;
  const strings = values && str ? new Array<string>(n * C) : null;
  const step = h.nominalRate > 0 ? 1 / h.nominalRate : 0;
  let p = start;
  for (let i = 0; i < n; i++) {
    const tsBytes = dv.getUint8(p);
    if (tsBytes === 8) {
      t[i] = dv.getFloat64(p + 1, true);
      p += 9;
    } else if (tsBytes === 0) {
      t[i] = clock.lastTimestamp + step;
      p += 1;
    } else {
      throw new Error(`sample ${i}: a timestamp of ${tsBytes} bytes (XDF has 0 or 8)`);
    }
    clock.lastTimestamp = t[i]!;
    if (str) {
      for (let k = 0; k < C; k++) {
        const [len, q] = readVarLen(dv, p);
        if (q + len > content.length) throw new Error(`sample ${i}: a string past the chunk`);
        if (strings) strings[i * C + k] = decoder.decode(content.subarray(q, q + len));
        p = q + len;
      }
    } else {
      if (vals) for (let k = 0; k < C; k++) vals[i * C + k] = readValue(dv, p + k * w, h.format);
      p += C * w;
    }
    if (p > content.length) throw new Error(`sample ${i} runs past the chunk`);
  }
  if (p !== content.length) {
    throw new Error(`${content.length - p} bytes after the ${n} samples the chunk announces`);
  }
  return { n, t, values: vals, strings };
}

// ---------------------------------------------------------------------------------------------
// Whole files

/** One stream of a file, everything read. */
export interface XdfStream {
  header: XdfStreamHeader;
  /** The footer's XML; undefined when the file has none for this stream (an interrupted one). */
  footer: string | undefined;
  t: Float64Array;
  /** Numeric streams: samples × channelCount values, row-major; null for string streams. */
  values: Float64Array | null;
  strings: string[] | null;
  clockOffsets: [number, number][];
}

export interface XdfFile {
  fileHeader: string;
  streams: XdfStream[];
  boundaries: number;
  /** Why reading stopped before the end ("" when the file ended after a whole chunk). */
  problem: string;
}

/** Reads a whole file into memory (tests, small recordings). */
export function readXdf(src: ByteSource): XdfFile {
  const r = new XdfChunkReader(src);
  let fileHeader = "";
  let boundaries = 0;
  const streams = new Map<number, XdfStream & { parts: XdfSamples[]; clock: SampleClock }>();
  for (let c = r.next(); c !== null; c = r.next()) {
    const content = r.content(c);
    if (c.tag === TAG_FILE_HEADER) fileHeader = decoder.decode(content);
    else if (c.tag === TAG_BOUNDARY) boundaries++;
    else if (c.tag === TAG_STREAM_HEADER) {
      let header: XdfStreamHeader;
      try {
        header = parseStreamHeader(c.streamId!, decoder.decode(content));
      } catch (e) {
        r.reject(c, `a damaged StreamHeader: ${(e as Error).message}`);
        break;
      }
      streams.set(c.streamId!, {
        header,
        footer: undefined,
        t: new Float64Array(0),
        values: null,
        strings: null,
        clockOffsets: [],
        parts: [],
        clock: { lastTimestamp: 0 },
      });
    } else {
      const s = streams.get(c.streamId!);
      if (s === undefined) {
        r.reject(c, `a chunk of stream ${c.streamId} before its StreamHeader`);
        break;
      }
      if (c.tag === TAG_SAMPLES) {
        try {
          s.parts.push(decodeSamples(content, s.header, s.clock));
        } catch (e) {
          r.reject(c, `a damaged Samples chunk of stream ${c.streamId}: ${(e as Error).message}`);
          break;
        }
      } else if (c.tag === TAG_CLOCK_OFFSET && c.contentLength === 16) {
        const dv = new DataView(content.buffer, content.byteOffset, 16);
        s.clockOffsets.push([dv.getFloat64(0, true), dv.getFloat64(8, true)]);
      } else if (c.tag === TAG_STREAM_FOOTER) {
        s.footer = decoder.decode(content);
      }
    }
  }
  return {
    fileHeader,
    boundaries,
    problem: r.problem,
    streams: [...streams.values()].map(({ parts, clock: _clock, ...s }) => concatParts(s, parts)),
  };
}

function concatParts(s: XdfStream, parts: XdfSamples[]): XdfStream {
  const n = parts.reduce((a, p) => a + p.n, 0);
  const C = s.header.channelCount;
  const t = new Float64Array(n);
  const str = s.header.format === "string";
  const values = str ? null : new Float64Array(n * C);
  const strings: string[] | null = str ? [] : null;
  let k = 0;
  for (const p of parts) {
    t.set(p.t, k);
    if (values && p.values) values.set(p.values, k * C);
    if (strings && p.strings) for (const x of p.strings) strings.push(x);
    k += p.n;
  }
  return { ...s, t, values, strings };
}
