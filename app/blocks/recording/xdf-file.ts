/**
 * One XDF file being recorded (https://github.com/sccn/xdf/wiki/Specifications): the header part
 * (magic, FileHeader, one StreamHeader per stream and a first ClockOffset each) goes out in one
 * write when the file is created; every `flush` writes what waited as ONE write: a Samples chunk
 * per stream with samples, a ClockOffset chunk per stream every 5 s and a Boundary chunk every
 * 10 s (as LabRecorder does); `close` adds a StreamFooter per stream. Every write reaches the
 * operating system at once (`FileWriteHandle`), so a killed recording keeps everything flushed: a
 * sequence of whole chunks, at worst with a torn last one, which XDF readers skip (pyxdf does) and
 * `mosaic repair` removes before adding the missing footers.
 */
import type { FileWriteHandle } from "../../engine";
import {
  ByteBuffer,
  fileHeaderXml,
  MarkerStream,
  NumericStream,
  putBoundary,
  putClockOffset,
  putXmlChunk,
  streamFooterXml,
  streamHeaderXml,
  TAG_FILE_HEADER,
  TAG_STREAM_FOOTER,
  TAG_STREAM_HEADER,
  XDF_MAGIC,
  type PendingStream,
  type StreamInfo,
} from "./xdf-writer";

/** Seconds between ClockOffset chunks (LabRecorder measures every 5 s). */
export const CLOCK_OFFSET_INTERVAL = 5;
/** Seconds between Boundary chunks (LabRecorder writes one every 10 s). */
export const BOUNDARY_INTERVAL = 10;

export class XdfFileWriter {
  readonly streams: readonly PendingStream[];
  private readonly out = new ByteBuffer(1 << 16);
  private nextOffset: number;
  private nextBoundary: number;
  private closed = false;

  /**
   * Writes the header part to `file`. `expected[i]` is about how many samples of stream i wait
   * between flushes (sizes its buffer; it grows if more come). Stream ids are 1, 2, … in order.
   */
  constructor(
    private readonly file: FileWriteHandle,
    infos: readonly StreamInfo[],
    now: number,
    datetime: string,
    expected: readonly number[] = [],
  ) {
    this.streams = infos.map((s, i) =>
      s.format === "string"
        ? new MarkerStream(i + 1)
        : new NumericStream(i + 1, s.channelCount, s.format, expected[i] ?? 256),
    );
    this.out.put(XDF_MAGIC);
    putXmlChunk(this.out, TAG_FILE_HEADER, null, fileHeaderXml(datetime));
    infos.forEach((s, i) => putXmlChunk(this.out, TAG_STREAM_HEADER, i + 1, streamHeaderXml(s)));
    this.putOffsets(now);
    this.nextOffset = now + CLOCK_OFFSET_INTERVAL;
    this.nextBoundary = now + BOUNDARY_INTERVAL;
    this.writeOut();
  }

  get path(): string {
    return this.file.path;
  }

  /** Bytes in the file. */
  get size(): number {
    return this.file.size;
  }

  /** Samples written to the file (all streams). */
  get samplesWritten(): number {
    let n = 0;
    for (const s of this.streams) n += s.written;
    return n;
  }

  /** Samples waiting for the next flush (all streams). */
  get samplesPending(): number {
    let n = 0;
    for (const s of this.streams) n += s.pending;
    return n;
  }

  get isClosed(): boolean {
    return this.closed;
  }

  /** Writes what waits, with the clock offsets and the boundary that are due at `now`. */
  flush(now: number): void {
    if (this.closed) return;
    for (const s of this.streams) s.takeChunk(this.out);
    if (now >= this.nextOffset) {
      this.putOffsets(now);
      this.nextOffset = now + CLOCK_OFFSET_INTERVAL;
    }
    if (now >= this.nextBoundary) {
      putBoundary(this.out);
      this.nextBoundary = now + BOUNDARY_INTERVAL;
    }
    this.writeOut();
  }

  /** Flushes, adds every stream's footer, asks the disk to keep it all and closes the file. */
  close(now: number): void {
    if (this.closed) return;
    try {
      for (const s of this.streams) s.takeChunk(this.out);
      this.putOffsets(now);
      for (const s of this.streams) {
        putXmlChunk(this.out, TAG_STREAM_FOOTER, s.id, streamFooterXml(s.summary()));
      }
      this.writeOut();
      this.file.sync();
    } finally {
      this.closed = true;
      this.file.close();
    }
  }

  /** Closes the file without writing anything more (after a write failed). */
  abandon(): void {
    if (this.closed) return;
    this.closed = true;
    try {
      this.file.close();
    } catch {
      // the file already failed; its first error is the one reported
    }
  }

  /** Our clock is the only clock: every offset is 0, measured at `now`. */
  private putOffsets(now: number): void {
    for (const s of this.streams) {
      putClockOffset(this.out, s.id, now, 0);
      s.clockOffsets.push([now, 0]);
    }
  }

  private writeOut(): void {
    if (this.out.length === 0) return;
    try {
      this.file.write(this.out.used);
    } finally {
      this.out.clear();
    }
  }
}
