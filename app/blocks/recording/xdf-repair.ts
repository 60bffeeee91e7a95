/**
 * Repair of an interrupted XDF recording (a killed process, a full disk): the file is scanned
 * chunk by chunk (https://github.com/sccn/xdf/wiki/Specifications), a torn or damaged last chunk
 * is dropped, and every stream without a StreamFooter gets one, with the first and last
 * timestamps, the sample count and the clock offsets read from its chunks, as LabRecorder writes
 * them at the end of a recording. The plan says what to keep of the file and what to append; the
 * caller (`mosaic repair`) writes it, as a copy or in place.
 */
import { ByteBuffer, putXmlChunk, streamFooterXml, TAG_STREAM_FOOTER } from "./xdf-writer";
import {
  decodeSamples,
  parseStreamHeader,
  utf8Decoder,
  XdfChunkReader,
  type ByteSource,
  type SampleClock,
  type XdfStreamHeader,
} from "./xdf-reader";

/** How to repair a file: keep its first `keep` bytes, then append `append`. */
export interface RepairPlan {
  keep: number;
  append: Uint8Array;
  /** False when the file is whole (nothing to do). */
  changed: boolean;
  /** What was found and what the repair does, one line each. */
  messages: string[];
}

interface StreamScan {
  header: XdfStreamHeader;
  hasFooter: boolean;
  count: number;
  first: number;
  last: number;
  clock: SampleClock;
  offsets: [number, number][];
}

const TAG_STREAM_HEADER = 2;
const TAG_SAMPLES = 3;
const TAG_CLOCK_OFFSET = 4;

const decoder = utf8Decoder;

/** Scans every chunk: per stream its header, samples, offsets and whether it has a footer. */
function scan(src: ByteSource): { reader: XdfChunkReader; streams: Map<number, StreamScan> } {
  const reader = new XdfChunkReader(src);
  const streams = new Map<number, StreamScan>();
  for (let c = reader.next(); c !== null; c = reader.next()) {
    if (c.streamId === null) continue;
    const s = streams.get(c.streamId);
    if (c.tag === TAG_STREAM_HEADER) {
      try {
        const header = parseStreamHeader(c.streamId, decoder.decode(reader.content(c)));
        streams.set(c.streamId, {
          header,
          hasFooter: false,
          count: 0,
          first: 0,
          last: 0,
          clock: { lastTimestamp: 0 },
          offsets: [],
        });
      } catch (e) {
        reader.reject(c, `a damaged StreamHeader: ${(e as Error).message}`);
        break;
      }
      continue;
    }
    if (s === undefined) {
      reader.reject(c, `a chunk of stream ${c.streamId} before its StreamHeader`);
      break;
    }
    if (c.tag === TAG_SAMPLES) {
      try {
        const got = decodeSamples(reader.content(c), s.header, s.clock, false);
        if (got.n > 0) {
          if (s.count === 0) s.first = got.t[0]!;
          s.last = got.t[got.n - 1]!;
          s.count += got.n;
        }
      } catch (e) {
        reader.reject(
          c,
          `a damaged Samples chunk of stream ${c.streamId}: ${(e as Error).message}`,
        );
        break;
      }
    } else if (c.tag === TAG_CLOCK_OFFSET) {
      if (c.contentLength !== 16) {
        reader.reject(c, `a ClockOffset chunk of ${c.contentLength} bytes (16 expected)`);
        break;
      }
      const b = reader.content(c);
      const dv = new DataView(b.buffer, b.byteOffset, 16);
      s.offsets.push([dv.getFloat64(0, true), dv.getFloat64(8, true)]);
    } else {
      s.hasFooter = true;
    }
  }
  return { reader, streams };
}

/** Plans the repair of the XDF file `src` (throws when it is not an XDF file at all). */
export function planXdfRepair(src: ByteSource): RepairPlan {
  const { reader, streams } = scan(src);
  const messages: string[] = [];
  const keep = reader.validEnd;
  if (keep < src.size) {
    messages.push(
      `dropped the last ${src.size - keep} bytes: ${reader.problem || "not a whole chunk"}`,
    );
  }
  const out = new ByteBuffer(1024);
  for (const [id, s] of streams) {
    if (s.hasFooter) continue;
    putXmlChunk(
      out,
      TAG_STREAM_FOOTER,
      id,
      streamFooterXml({
        firstTimestamp: s.first,
        lastTimestamp: s.last,
        sampleCount: s.count,
        clockOffsets: s.offsets,
      }),
    );
    messages.push(
      `stream ${id} '${s.header.name}': added its footer (${s.count} samples` +
        (s.count > 0 ? `, ${s.first} … ${s.last} s` : "") +
        ")",
    );
  }
  if (streams.size === 0) messages.push("the file holds no stream");
  const changed = keep < src.size || out.length > 0;
  if (!changed) messages.push("whole: every stream has its footer, nothing to repair");
  return { keep, append: out.used.slice(), changed, messages };
}
