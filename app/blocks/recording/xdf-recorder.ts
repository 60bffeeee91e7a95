import { z } from "zod";
import { defineBlock, type BlockContext, type Frame } from "../../engine";
import { formatCount, TextThrottle } from "../shared/text";
import { XdfFileWriter } from "./xdf-file";
import {
  expandFileName,
  formatBytes,
  numberedName,
  planStreams,
  streamSettings,
  type PlannedStream,
} from "./xdf-streams";
import { MarkerStream, NumericStream } from "./xdf-writer";

/** Seconds between writes: each write holds ~100 ms of every stream as one Samples chunk. */
export const XDF_FLUSH_INTERVAL = 0.1;
/** Most numbered alternatives tried when the file's name is taken. */
const MAX_NUMBERED = 999;

const params = z.strictObject({
  File: z
    .string()
    .min(1)
    .default("recordings/{date}_{time}.xdf")
    .describe(
      "The XDF file, relative to the pipeline file; {date}, {time} (local) and {block} are replaced, and a taken name gets _2, _3, … (nothing is overwritten)",
    ),
  Recording: z
    .boolean()
    .default(true)
    .describe(
      "Record; false closes the file (with its footers), true opens a new one (can be changed while running)",
    ),
  Overwrite: z
    .boolean()
    .default(false)
    .describe(
      "Replace a file of the same name instead of numbering the new one (benchmarks, scratch runs)",
    ),
  Format: z
    .enum(["float32", "double64"])
    .default("float32")
    .describe(
      "Value format of signal streams (float32 as most devices; double64 keeps every value exact)",
    ),
  Streams: z
    .record(z.string(), streamSettings)
    .default({})
    .describe(
      "Per input (as written in Inputs): Name, Type, Labels, Unit, Format of its stream, e.g. { Emg: { Type: EMG, Unit: microvolts } }",
    ),
});
type Params = z.output<typeof params>;

export const XdfRecorder = defineBlock({
  type: "XdfRecorder",
  category: "Recording",
  summary:
    "Records its inputs into one XDF file as LabRecorder does; a killed recording stays readable.",
  help:
    "Records every input as one stream of an XDF file (https://github.com/sccn/xdf/wiki/Specifications), " +
    "the format of LabRecorder and the Lab Streaming Layer, read by pyxdf, MNE, EEGLAB and " +
    "MoBILAB: a FileHeader, a StreamHeader per input (name, type, channel_count, nominal_srate, " +
    "channel_format, source_id and desc/channels/channel/label), Samples chunks with every " +
    "sample's timestamp (the pipeline clock, UNIX seconds), a ClockOffset chunk per stream every " +
    "5 s (offset 0: every stream has the pipeline's clock), a Boundary chunk every 10 s and a " +
    "StreamFooter per stream when the file is closed. Events (a Stimulus's `trigger`, a " +
    "Trigger's, StimTrigger's or TAC's outputs) become string marker streams (irregular rate, " +
    "one channel: the event's values joined by commas, NaN for a stop); signals are float32 " +
    "(`Format: double64` keeps every value exact). A matrix input is written row by row. " +
    "Crash-safe: what arrives is serialised at once and written every 0.1 s, each write going to " +
    "the operating system at once, so a killed process loses at most the last ~0.1 s and the file " +
    "opens without its footers; `mosaic repair FILE.xdf` adds them. The file opens when the " +
    "pipeline starts (or with `start`), `stop` or `Recording: false` closes it, and `start` " +
    "opens a new one. In the browser build the file is kept in memory and downloaded when it " +
    "closes (at stop, or with `stop`); where a runtime has no file access at all it records " +
    "nothing and says so in its status.",
  params,
  inputs: { min: 1, max: Infinity },
  outputs: [],
  live: ["Recording"],
  views: ["label"],
  panel: "The file, the duration, size and samples written, and start/stop buttons.",
  create(ctx, p: Params) {
    const planned = planStreams(ctx, p.Format, p.Streams);
    return new Recorder(ctx, p, planned).instance();
  },
});

/** The XdfRecorder's state: at most one file open at a time. */
class Recorder {
  private writer: XdfFileWriter | null = null;
  private numeric: (NumericStream | null)[] = [];
  private markers: (MarkerStream | null)[] = [];
  private recording: boolean;
  private started = false;
  private openedAt = 0;
  private nextFlush = Infinity;
  private armed = false;
  private files = 0;
  private lastFile = "";
  private failure = "";
  private readonly throttle = new TextThrottle(0.5);
  private readonly flushAt = (t: number): void => {
    this.armed = false;
    if (this.writer !== null && t >= this.nextFlush) this.flush(t);
    if (this.writer !== null && this.writer.samplesPending > 0) this.arm();
  };

  constructor(
    private readonly ctx: BlockContext,
    private readonly p: Params,
    private readonly planned: readonly PlannedStream[],
  ) {
    this.recording = p.Recording;
  }

  instance() {
    return {
      start: () => {
        this.started = true;
        if (this.recording) this.open();
        else this.describe();
      },
      process: (f: Frame, port: number) => this.process(f, port),
      stop: () => {
        this.close();
        this.started = false;
      },
      dispose: () => this.close(),
      setParam: (name: string, value: unknown) => {
        if (name === "Recording") this.setRecording(value as boolean);
      },
      actions: {
        start: {
          label: "Start recording",
          description: "Open a new XDF file and record into it",
          run: () => this.setRecording(true),
        },
        stop: {
          label: "Stop recording",
          description: "Close the file (with its footers)",
          run: () => this.setRecording(false),
        },
      },
    };
  }

  private process(f: Frame, port: number): void {
    if (this.writer === null || f.n === 0) return;
    const num = this.numeric[port];
    if (num) num.append(f.t, f.v, f.n, f.stride);
    else this.appendMarkers(this.markers[port]!, f);
    const now = this.ctx.now();
    if (now >= this.nextFlush) this.flush(now);
    else this.arm();
  }

  /** Each event as one marker: its values in shortest round-trip form, joined by commas. */
  private appendMarkers(m: MarkerStream, f: Frame): void {
    const s = f.stride;
    for (let i = 0; i < f.n; i++) {
      let text = "";
      for (let k = 0; k < s; k++) text += (k > 0 ? "," : "") + String(f.v[i * s + k]);
      m.append(f.t[i]!, text);
    }
  }

  /** Arms the one-shot that flushes when no frame comes to do it. */
  private arm(): void {
    if (this.armed || this.writer === null || !Number.isFinite(this.nextFlush)) return;
    this.armed = true;
    this.ctx.at(this.nextFlush, this.flushAt);
  }

  private flush(now: number): void {
    const w = this.writer!;
    try {
      w.flush(now);
    } catch (e) {
      this.fail(e);
      return;
    }
    this.nextFlush = now + XDF_FLUSH_INTERVAL;
    if (this.throttle.due(now)) this.describe();
  }

  private open(): void {
    if (this.writer !== null) return;
    const res = this.ctx.resources;
    if (res.openWrite === undefined) {
      this.failure = "no file access in this runtime: nothing is recorded";
      this.describe();
      return;
    }
    const now = this.ctx.now();
    const base = expandFileName(this.p.File, now, this.ctx.name);
    try {
      const { name, handle } = this.p.Overwrite
        ? { name: base, handle: res.openWrite(base, { overwrite: true }) }
        : openNumbered(base, (n) => res.openWrite!(n));
      const infos = this.planned.map((s, i) => ({
        ...s,
        createdAt: now,
        uid: `${this.ctx.name}-${i + 1}-${now}`,
      }));
      const expected = this.planned.map((s) =>
        Math.ceil(Math.max(s.nominalRate, 1) * XDF_FLUSH_INTERVAL * 2),
      );
      this.writer = new XdfFileWriter(handle, infos, now, isoTime(now), expected);
      this.lastFile = name;
    } catch (e) {
      this.fail(e);
      return;
    }
    this.numeric = this.writer.streams.map((s) => (s instanceof NumericStream ? s : null));
    this.markers = this.writer.streams.map((s) => (s instanceof MarkerStream ? s : null));
    this.files++;
    this.failure = "";
    this.openedAt = now;
    this.nextFlush = now + XDF_FLUSH_INTERVAL;
    this.throttle.reset();
    this.describe();
  }

  private close(): void {
    const w = this.writer;
    if (w === null) return;
    try {
      w.close(this.ctx.now());
    } catch (e) {
      this.fail(e);
      return;
    }
    this.writer = null;
    this.nextFlush = Infinity;
    this.describe(w);
  }

  /** A write failed (disk full, file removed): reported once, the recording stops. */
  private fail(e: unknown): void {
    const msg = (e as Error).message;
    this.failure = `not recording: ${msg}`;
    this.ctx.error(`XDF recording failed: ${msg}`);
    this.writer?.abandon();
    this.writer = null;
    this.recording = false;
    this.nextFlush = Infinity;
    this.describe();
  }

  private setRecording(on: boolean): string {
    this.recording = on;
    if (!this.started) {
      this.describe();
      return on ? "will record when the pipeline starts" : "will not record";
    }
    if (on) this.open();
    else this.close();
    if (this.failure !== "") return this.failure;
    return on ? `recording to ${this.lastFile}` : `recording stopped: ${this.lastFile} closed`;
  }

  private describe(closed?: XdfFileWriter): void {
    if (this.failure !== "") {
      this.ctx.setText(this.failure);
      return;
    }
    const w = this.writer ?? closed;
    if (w === undefined || w === null) {
      this.ctx.setText(this.recording ? "ready to record" : "not recording (start to record)");
      return;
    }
    const duration = Math.max(0, this.ctx.now() - this.openedAt).toFixed(1);
    const facts =
      `${duration} s, ${formatBytes(w.size)}, ${formatCount(w.samplesWritten)} samples` +
      (this.files > 1 ? `, file ${this.files}` : "");
    this.ctx.setText(
      this.writer !== null
        ? `recording ${this.lastFile}: ${facts}`
        : `closed ${this.lastFile}: ${facts}`,
    );
  }
}

/** Opens `base`, or `base_2`, `base_3`, … when the name is taken. */
function openNumbered<H>(base: string, open: (name: string) => H): { name: string; handle: H } {
  for (let k = 1; k <= MAX_NUMBERED; k++) {
    const name = numberedName(base, k);
    try {
      return { name, handle: open(name) };
    } catch (e) {
      if (!/exists already/.test((e as Error).message)) throw e;
    }
  }
  throw new Error(`${base} and ${MAX_NUMBERED - 1} numbered alternatives exist already`);
}

/** The file header's datetime: ISO 8601 (UTC) of clock time `t`. */
function isoTime(t: number): string {
  const d = new Date(t * 1000);
  return Number.isFinite(d.getTime()) ? d.toISOString() : "";
}
