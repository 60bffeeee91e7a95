/**
 * A session recording (the UI's Record button): block outputs, chosen at run time, recorded into
 * one file without editing the pipeline. Each output is tapped (`Runtime.tap`, as panels are) and
 * its frames go to a format's writer (XDF, EDF+, BDF+: injected, see format.ts); what waits is
 * written every 0.1 s from the session's telemetry tick. Where the host writes files
 * (`Resources.openWrite`, confined to the allowed folders) the file goes to `recordings/` with a
 * name from the date and time; elsewhere (the browser build) it is kept in memory and its bytes
 * are returned when it stops, for a download. A failing write stops the recording and says why;
 * it never disturbs the pipeline.
 */
import type { FileWriteHandle, Resources } from "../block";
import type { Frame } from "../frame";
import type { RecordingFormatName, RecordingStatus } from "../protocol";
import type { Runtime } from "../runtime/runtime";
import type { RecordedOutput, RecordingFormat, RecordingFormats, RecordingWriter } from "./format";
import { MemoryFile } from "./memory-file";

/** Seconds between writes. */
export const RECORDING_FLUSH_S = 0.1;
/** The folder (relative to the pipeline's) that recordings go to. */
export const RECORDINGS_FOLDER = "recordings";
const MAX_NUMBERED = 999;

export interface RecordingRequest {
  outputs: readonly { block: string; port?: string | undefined }[];
  format: RecordingFormatName;
  /** A plain file name (no folder); default: `<date>_<time>.<ext>`. */
  file?: string | undefined;
}

/** The file a recording left: its status, and its bytes when it was kept in memory. */
export interface FinishedRecording {
  status: RecordingStatus;
  bytes?: Uint8Array;
  mime: string;
}

const pad = (n: number): string => String(n).padStart(2, "0");

/** `2026-11-24_09-41-07` (local time of `t`, UNIX seconds). */
export function recordingStamp(t: number): string {
  const d = new Date(t * 1000);
  return (
    `${d.getFullYear()}-${pad(d.getMonth() + 1)}-${pad(d.getDate())}_` +
    `${pad(d.getHours())}-${pad(d.getMinutes())}-${pad(d.getSeconds())}`
  );
}

/** The file name: a plain name (checked) with the format's extension, or one from the time. */
export function recordingName(file: string | undefined, ext: string, t: number): string {
  if (file === undefined) return `${recordingStamp(t)}.${ext}`;
  const name = file.trim();
  if (name === "" || /[/\\]/.test(name) || name.startsWith(".")) {
    throw new Error(
      `the recording's file must be a plain name without a folder (got '${file}'): recordings go to the ${RECORDINGS_FOLDER} folder`,
    );
  }
  return name.toLowerCase().endsWith(`.${ext}`) ? name : `${name}.${ext}`;
}

/** rec.xdf → rec_2.xdf, rec_3.xdf, … */
function numbered(name: string, k: number): string {
  if (k <= 1) return name;
  const dot = name.lastIndexOf(".");
  return dot > 0 ? `${name.slice(0, dot)}_${k}${name.slice(dot)}` : `${name}_${k}`;
}

/** Opens `recordings/<name>` (or a numbered alternative when taken). */
function openOnDisk(open: (path: string) => FileWriteHandle, name: string): FileWriteHandle {
  for (let k = 1; ; k++) {
    try {
      return open(`${RECORDINGS_FOLDER}/${numbered(name, k)}`);
    } catch (e) {
      if (!/exists already/.test((e as Error).message) || k >= MAX_NUMBERED) throw e;
    }
  }
}

/** The outputs as the file describes them; throws naming an unknown block or port. */
export function resolveOutputs(rt: Runtime, wanted: RecordingRequest["outputs"]): RecordedOutput[] {
  const seen = new Set<string>();
  return wanted.map(({ block, port }) => {
    const node = rt.node(block);
    if (!node) throw new Error(`no block '${block}' in the pipeline`);
    const p = port === undefined ? node.ports[0] : node.ports.find((x) => x.name === port);
    if (!p) {
      throw new Error(
        port === undefined
          ? `block '${block}' has no output to record`
          : `block '${block}' has no output '${port}' (it has ${node.ports.map((x) => x.name).join(", ") || "none"})`,
      );
    }
    const isDefault = p === node.ports[0];
    const source = isDefault ? block : `${block}.${p.name}`;
    if (seen.has(source)) throw new Error(`output ${source} is listed twice`);
    seen.add(source);
    if (p.shape.rows * p.shape.cols === 0) {
      throw new Error(`output ${source} carries no values (a timer's ticks): nothing to record`);
    }
    return {
      block,
      port: p.name,
      source,
      blockType: node.def.type,
      shape: p.shape,
      rate: node.desiredRate,
      ...(p.meta ? { meta: p.meta } : {}),
    };
  });
}

export class SessionRecorder {
  private readonly untaps: (() => void)[] = [];
  private nextFlush: number;
  private failure = "";
  private done = false;
  /** When it ended (finished or failed), and the latest time seen. */
  private endedAt: number | undefined;
  private lastNow: number;

  private constructor(
    private readonly format: RecordingFormat,
    private readonly formatName: RecordingFormatName,
    private readonly outputs: readonly RecordedOutput[],
    private readonly file: FileWriteHandle,
    private readonly writer: RecordingWriter,
    private readonly startedAt: number,
    private readonly memory: MemoryFile | null,
  ) {
    this.nextFlush = startedAt + RECORDING_FLUSH_S;
    this.lastNow = startedAt;
  }

  /** Opens the file and taps the outputs; throws with a message when it cannot. */
  static start(
    rt: Runtime,
    req: RecordingRequest,
    formats: RecordingFormats,
    resources: Resources,
  ): SessionRecorder {
    const format = formats[req.format];
    if (!format) throw new Error(`this engine cannot record ${req.format.toUpperCase()} files`);
    const outputs = resolveOutputs(rt, req.outputs);
    const planned = format.plan(outputs);
    const now = rt.clock.now();
    const name = recordingName(req.file, format.extension, now);
    const write = resources.openWrite?.bind(resources);
    const memory = write ? null : new MemoryFile(name);
    const file = write ? openOnDisk((path) => write(path), name) : memory!;
    let writer: RecordingWriter;
    try {
      writer = planned.open(file, now);
    } catch (e) {
      file.close();
      throw e;
    }
    const r = new SessionRecorder(format, req.format, outputs, file, writer, now, memory);
    outputs.forEach((o, i) => r.untaps.push(rt.tap(o.block, o.port, (f) => r.append(i, f))));
    return r;
  }

  get failed(): boolean {
    return this.failure !== "";
  }

  /** Hot path: one frame of output `i`. */
  private append(i: number, f: Frame): void {
    if (this.done) return;
    try {
      this.writer.append(i, f);
    } catch (e) {
      this.fail(e);
    }
  }

  /** Writes what waits when a write is due (the session's telemetry tick). */
  tick(now: number): void {
    this.lastNow = now;
    if (this.done || now < this.nextFlush) return;
    this.nextFlush = now + RECORDING_FLUSH_S;
    try {
      this.writer.flush(now);
    } catch (e) {
      this.fail(e);
    }
  }

  /** Finishes the file (its end written, closed); the bytes when it was kept in memory. */
  stop(now: number): FinishedRecording {
    if (!this.done) {
      this.untapAll();
      this.done = true;
      try {
        this.writer.close(now);
      } catch (e) {
        this.failure = (e as Error).message;
        this.writer.abandon();
      }
      this.endedAt = now;
    }
    const status = this.status(now);
    return {
      status,
      mime: this.format.mime,
      ...(this.memory && this.memory.size > 0 ? { bytes: this.memory.bytes } : {}),
    };
  }

  status(now: number): RecordingStatus {
    const end = this.endedAt ?? now;
    return {
      state: this.failure !== "" ? "failed" : this.done ? "finished" : "recording",
      file: this.file.path,
      format: this.formatName,
      outputs: this.outputs.map((o) => o.source),
      duration: Math.max(0, end - this.startedAt),
      bytes: this.file.size,
      samples: this.writer.samplesWritten,
      inMemory: this.memory !== null,
      ...(this.failure !== "" ? { error: this.failure } : {}),
    };
  }

  /** A write failed (disk full, file removed): the recording stops and keeps what it wrote. */
  private fail(e: unknown): void {
    this.failure = (e as Error).message;
    this.done = true;
    this.endedAt = this.lastNow;
    this.untapAll();
    this.writer.abandon();
  }

  private untapAll(): void {
    for (const u of this.untaps.splice(0)) u();
  }
}
