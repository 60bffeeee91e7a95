/**
 * What a session recording (session-recorder.ts) asks of a file format. The formats themselves
 * (XDF, EDF+, BDF+) live with the recorder blocks in app/blocks/recording/ and are injected by the
 * host (SessionPlatform.recordingFormats): the engine does not import blocks.
 */
import type { FileWriteHandle, PortMeta } from "../block";
import type { Frame, Shape } from "../frame";
import type { RecordingFormatName } from "../protocol";

/** One output being recorded: what the file says about it. */
export interface RecordedOutput {
  block: string;
  port: string;
  /** "Emg" for a block's default port, "Emg.imu" for another. */
  source: string;
  /** The block's type (e.g. "EmgSimulator"): the stream's content type, marker detection. */
  blockType: string;
  shape: Shape;
  /** Desired rate, Hz; 0 when aperiodic. */
  rate: number;
  meta?: PortMeta;
}

/** One file being written. Errors are thrown with a message saying what is wrong. */
export interface RecordingWriter {
  /** Takes the events of output `index`'s frame (copies what it keeps). Runs on the hot path. */
  append(index: number, f: Frame): void;
  /** Writes what waits (called every ~0.1 s). */
  flush(now: number): void;
  /** Writes what waits and the file's end, and closes the file. */
  close(now: number): void;
  /** Closes the file without writing more (after an error). */
  abandon(): void;
  /** Samples (events) written to the file so far, all outputs. */
  readonly samplesWritten: number;
}

export interface RecordingFormat {
  /** File extension without the dot. */
  readonly extension: string;
  /** MIME type of a download. */
  readonly mime: string;
  /**
   * Plans the file before any exists (throws when the outputs do not fit the format, e.g. an
   * EDF+ of outputs without a rate); `open` then writes its beginning to `file`.
   */
  plan(outputs: readonly RecordedOutput[]): PlannedRecording;
}

export interface PlannedRecording {
  open(file: FileWriteHandle, now: number): RecordingWriter;
}

export type RecordingFormats = Readonly<Partial<Record<RecordingFormatName, RecordingFormat>>>;
