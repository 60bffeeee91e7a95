/**
 * One EdfRecorder at run time (`EdfRecording`): the file it records to, started and stopped by
 * the pipeline, the Recording param and the start/stop actions, its inputs' samples and markers
 * written to the stream, and the status text.
 */
import { type BlockContext, type FileWriteHandle, type Frame } from "../../engine";
import { formatCount, TextThrottle } from "../shared/text";
import {
  edfFileName,
  MAX_MARKER_TEXT,
  type EdfParams,
  type EdfSetup,
  type MarkerSlot,
} from "./edf-setup";
import { EdfStream } from "./edf-stream";
import { annotationText } from "./edf-writer";

/** Records ahead one input may get of another before the other is padded (about 2 s). */
export const lagRecords = (recordUs: number): number => Math.max(2, Math.ceil(2e6 / recordUs));
const MAX_NUMBERED = 999;

function sizeText(bytes: number): string {
  if (bytes < 1024) return `${bytes} B`;
  if (bytes < 1024 * 1024) return `${(bytes / 1024).toFixed(1)} KiB`;
  return `${(bytes / 1024 / 1024).toFixed(1)} MiB`;
}

/** The text of a marker event: `Source=v1,v2` (at most 16 values). */
export function markerText(source: string, f: Frame, i: number): string {
  const n = Math.min(f.stride, 16);
  const parts: string[] = [];
  for (let k = 0; k < n; k++) parts.push(String(f.v[i * f.stride + k]));
  if (f.stride > n) parts.push("...");
  return annotationText(`${source}=${parts.join(",")}`, MAX_MARKER_TEXT);
}

/** Whether event `i` of `f` differs from the previous one of its input (kept in `last`). */
export function changed(f: Frame, i: number, last: { v: Float64Array | null }): boolean {
  const s = f.stride;
  const at = i * s;
  const prev = last.v;
  if (prev !== null) {
    let same = true;
    for (let k = 0; k < s && same; k++) same = Object.is(f.v[at + k], prev[k]);
    if (same) return false;
  }
  last.v = f.v.slice(at, at + s);
  return true;
}

/** One recording: its file and stream. */
interface Session {
  file: FileWriteHandle;
  stream: EdfStream;
  name: string;
}

/** Opens the first free name of the File pattern. */
function openFile(
  ctx: BlockContext,
  p: EdfParams,
  setup: EdfSetup,
): { file: FileWriteHandle; name: string } {
  const openWrite = ctx.resources.openWrite!.bind(ctx.resources);
  const t = ctx.now();
  for (let n = 1; ; n++) {
    const name = edfFileName(p.File, ctx.name, t, setup.format, n);
    try {
      return { file: openWrite(name), name };
    } catch (e) {
      const m = (e as Error).message;
      if (!/exists already/.test(m) || n >= MAX_NUMBERED) throw e;
    }
  }
}

function describeSession(s: Session, recordUs: number, stopped: boolean): string {
  const c = s.stream.counts;
  const parts = [
    `${s.name}: ${((c.records * recordUs) / 1e6).toFixed(1)} s`,
    sizeText(s.file.size),
    `${formatCount(c.records)} records`,
    `${formatCount(c.clipped)} clipped`,
  ];
  if (c.nan > 0) parts.push(`${formatCount(c.nan)} NaN`);
  if (c.padded > 0)
    parts.push(`${formatCount(c.padded)} padded, ${formatCount(c.dropped)} dropped`);
  if (c.annotations > 0) parts.push(`${formatCount(c.annotations)} annotations`);
  if (c.annotationsLost > 0) parts.push(`${formatCount(c.annotationsLost)} annotations lost`);
  return (stopped ? "stopped: " : "") + parts.join(", ");
}

/** A recording block's state: the open session, the last one, and whether it should record. */
export class EdfRecording {
  /** Signal of each input (-1: a marker input). */
  private readonly signalOf: Int32Array;
  private readonly markerOf: Map<number, MarkerSlot>;
  /** The last value of each marker input, for those marked on change. */
  private readonly lastMarker: { v: Float64Array | null }[];
  private session: Session | null = null;
  private last: Session | null = null;
  private recording: boolean;
  private running = false;
  private readonly throttle = new TextThrottle();

  constructor(
    private readonly ctx: BlockContext,
    private readonly p: EdfParams,
    private readonly setup: EdfSetup,
  ) {
    this.signalOf = new Int32Array(ctx.inputs.length).fill(-1);
    setup.signals.forEach((s, k) => (this.signalOf[s.index] = k));
    this.markerOf = new Map<number, MarkerSlot>(setup.markers.map((m) => [m.index, m]));
    this.lastMarker = setup.markers.map(() => ({ v: null as Float64Array | null }));
    this.recording = p.Recording;
  }

  start(): void {
    this.running = true;
    if (this.recording) this.begin();
    else this.describe();
  }

  process(f: Frame, port: number): void {
    const session = this.session;
    if (!session || f.n === 0) return;
    try {
      const k = this.signalOf[port]!;
      if (k >= 0) session.stream.append(k, f.t[0]!, f.v, f.n * this.setup.signals[k]!.rows);
      else this.mark(this.markerOf.get(port)!, f);
    } catch (e) {
      this.fail(e);
      return;
    }
    if (this.throttle.due(f.t[f.n - 1]!)) this.describe();
  }

  stop(): void {
    this.running = false;
    this.end();
  }

  /** Recording on or off (the param and the actions); returns the action's answer. */
  setRecording(on: boolean): string {
    this.recording = on;
    if (on && this.running) this.begin();
    if (!on) this.end();
    this.describe();
    const s = this.session ?? this.last;
    return on
      ? `recording to ${s?.name ?? "(no file)"}`
      : `recording stopped (${s?.name ?? "no file"})`;
  }

  /** Finishes the file being recorded, if any. */
  end(): void {
    const s = this.session;
    if (!s) return;
    this.session = null;
    this.last = s;
    try {
      s.file.sync();
    } catch (e) {
      this.ctx.error(`cannot finish ${s.name}: ${(e as Error).message}`);
    }
    s.file.close();
    this.describe();
  }

  private describe(): void {
    const { ctx, session, last } = this;
    if (!ctx.resources.openWrite) {
      ctx.setText("no file access in this runtime: nothing is recorded");
    } else if (session) ctx.setText(describeSession(session, this.setup.duration.us, false));
    else if (last) ctx.setText(describeSession(last, this.setup.duration.us, true));
    else ctx.setText(this.recording ? "waiting for the pipeline to start" : "stopped");
  }

  /** Opens a new file (unless one is open or there is no file access). */
  private begin(): void {
    const ctx = this.ctx;
    if (this.session || !ctx.resources.openWrite) return this.describe();
    try {
      const { file, name } = openFile(ctx, this.p, this.setup);
      this.session = { file, stream: this.openStream(file), name };
      this.lastMarker.forEach((m) => (m.v = null));
    } catch (e) {
      ctx.error(`cannot record: ${(e as Error).message}`);
      ctx.setText(`cannot record: ${(e as Error).message}`);
      return;
    }
    this.describe();
  }

  private openStream(file: FileWriteHandle): EdfStream {
    const setup = this.setup;
    return new EdfStream(
      {
        format: setup.format,
        inputs: setup.streamInputs,
        recordUs: setup.duration.us,
        recordText: setup.duration.text,
        annotationBytes: setup.annotationBytes,
        patient: this.p.Patient,
        recording: "X X MOSAIC",
        maxLagRecords: lagRecords(setup.duration.us),
      },
      file,
    );
  }

  private fail(e: unknown): void {
    const name = this.session?.name ?? "the file";
    this.end();
    this.ctx.error(`recording to ${name} stopped: ${(e as Error).message}`);
  }

  private mark(m: MarkerSlot, f: Frame): void {
    const k = this.setup.markers.indexOf(m);
    for (let i = 0; i < f.n; i++) {
      if (m.onChange && !changed(f, i, this.lastMarker[k]!)) continue;
      this.session!.stream.annotate(f.t[i]!, markerText(m.source, f, i));
    }
  }
}
