import { defineBlock, type BlockContext, type FileWriteHandle, type Frame } from "../../engine";
import { formatCount, TextThrottle } from "../shared/text";
import {
  edfFileName,
  edfParams,
  MAX_MARKER_TEXT,
  resolveEdfSetup,
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

export const EdfRecorder = defineBlock({
  type: "EdfRecorder",
  category: "Recording",
  summary:
    "Records its inputs into one continuous EDF+ (16-bit) or BDF+ (24-bit) file, markers as annotations; crash-safe.",
  help:
    "Writes the clinical standard read by EDFbrowser, MNE, EEGLAB and pyedflib: EDF+ " +
    "(https://www.edfplus.info/specs/edf.html, /edfplus.html) with 16-bit samples or BDF+ " +
    "(BioSemi's https://www.biosemi.com/faq/file_format.htm with the EDF+ header) with 24-bit " +
    "samples, continuous (EDF+C/BDF+C). Every channel of every periodic input is a signal of the " +
    "file (a matrix input's rows are consecutive samples, as a device's packets); inputs of " +
    "different rates share the file. The data-record duration is chosen so every rate gives a " +
    "whole number of samples: each rate is read as the simplest fraction within half its third " +
    "decimal (1925.926 Hz = 52000/27), the shortest common duration is made a decimal of at most " +
    "6 decimals (0.027 s holds 52 Trigno samples, 0.0005 s one at 2000 Hz), and the longest " +
    "multiple of it up to 0.5 s that keeps a record within 61 440 bytes is taken (an error names " +
    "the inputs when no duration up to 60 s fits). Samples are written as " +
    "digital = round((x − min)·(dmax − dmin)/(max − min) + dmin) with the physical range as the " +
    "header holds it (PhysicalRange, or per input ±10× the largest value of its first record) and " +
    "the format's digital range; values outside are clipped and NaN written as dmin, both " +
    "counted. The 'EDF Annotations' signal carries each record's time-keeping TAL (the first " +
    "record's onset is the fraction of a second at which the recording starts: the header keeps " +
    "whole seconds, UTC) and markers: aperiodic inputs (a Trigger's), the event outputs of " +
    "Stimulus, StimTrigger and TAC, or the inputs named in Markers give an annotation " +
    "`Input=v1,v2` at the event's time — on every event of an aperiodic input, when the value " +
    "changes for a periodic one. Crash-safe: each data record is written as soon as every input " +
    "has filled it and the header's record count is rewritten after it, so a killed recording " +
    "loses at most the record being filled (< 0.5 s by default) and opens in any reader; " +
    "`mosaic repair FILE` fixes files from older or interrupted recorders. The header is written " +
    "with the first record (its start time is the earliest first sample). An input that falls " +
    "about 2 s behind another has its last value held to keep the file going, and as many of its " +
    "late samples are dropped: both counted. `stop` (or Recording: false) finishes the file " +
    "(samples of an incomplete last record are not written); `start` begins a new one. In the " +
    "browser build the file is kept in memory and downloaded when it is finished; where a " +
    "runtime has no file access at all it records nothing and says so.",
  params: edfParams,
  inputs: { min: 1, max: Infinity },
  outputs: [],
  live: ["Recording"],
  views: ["label"],
  panel: "The file, its duration, size, records and clipped samples, with start/stop buttons.",
  create(ctx, p) {
    const setup = resolveEdfSetup(ctx, p);
    const signalOf = new Int32Array(ctx.inputs.length).fill(-1);
    setup.signals.forEach((s, k) => (signalOf[s.index] = k));
    const markerOf = new Map<number, MarkerSlot>(setup.markers.map((m) => [m.index, m]));
    const lastMarker = setup.markers.map(() => ({ v: null as Float64Array | null }));
    let session: Session | null = null;
    let last: Session | null = null;
    let recording = p.Recording;
    let running = false;
    const throttle = new TextThrottle();

    const describe = () => {
      if (!ctx.resources.openWrite) {
        ctx.setText("no file access in this runtime: nothing is recorded");
      } else if (session) ctx.setText(describeSession(session, setup.duration.us, false));
      else if (last) ctx.setText(describeSession(last, setup.duration.us, true));
      else ctx.setText(recording ? "waiting for the pipeline to start" : "stopped");
    };
    const begin = () => {
      if (session || !ctx.resources.openWrite) return describe();
      try {
        const { file, name } = openFile(ctx, p, setup);
        const stream = new EdfStream(
          {
            format: setup.format,
            inputs: setup.streamInputs,
            recordUs: setup.duration.us,
            recordText: setup.duration.text,
            annotationBytes: setup.annotationBytes,
            patient: p.Patient,
            recording: "X X MOSAIC",
            maxLagRecords: lagRecords(setup.duration.us),
          },
          file,
        );
        session = { file, stream, name };
        lastMarker.forEach((m) => (m.v = null));
      } catch (e) {
        ctx.error(`cannot record: ${(e as Error).message}`);
        ctx.setText(`cannot record: ${(e as Error).message}`);
        return;
      }
      describe();
    };
    const end = () => {
      const s = session;
      if (!s) return;
      session = null;
      last = s;
      try {
        s.file.sync();
      } catch (e) {
        ctx.error(`cannot finish ${s.name}: ${(e as Error).message}`);
      }
      s.file.close();
      describe();
    };
    const fail = (e: unknown) => {
      const name = session?.name ?? "the file";
      end();
      ctx.error(`recording to ${name} stopped: ${(e as Error).message}`);
    };
    const setRecording = (on: boolean): string => {
      recording = on;
      if (on && running) begin();
      if (!on) end();
      describe();
      const s = session ?? last;
      return on
        ? `recording to ${s?.name ?? "(no file)"}`
        : `recording stopped (${s?.name ?? "no file"})`;
    };
    const mark = (m: MarkerSlot, f: Frame) => {
      const k = setup.markers.indexOf(m);
      for (let i = 0; i < f.n; i++) {
        if (m.onChange && !changed(f, i, lastMarker[k]!)) continue;
        session!.stream.annotate(f.t[i]!, markerText(m.source, f, i));
      }
    };
    return {
      start() {
        running = true;
        if (recording) begin();
        else describe();
      },
      process(f, port) {
        if (!session || f.n === 0) return;
        try {
          const k = signalOf[port]!;
          if (k >= 0) session.stream.append(k, f.t[0]!, f.v, f.n * setup.signals[k]!.rows);
          else mark(markerOf.get(port)!, f);
        } catch (e) {
          fail(e);
          return;
        }
        if (throttle.due(f.t[f.n - 1]!)) describe();
      },
      stop() {
        running = false;
        end();
      },
      dispose() {
        end();
      },
      setParam(name, value) {
        if (name === "Recording") setRecording(value as boolean);
      },
      actions: {
        start: {
          label: "Start recording",
          description: "Begin a new file (the File pattern's next free name)",
          run: () => setRecording(true),
        },
        stop: {
          label: "Stop recording",
          description: "Finish the file (its header is complete after every record already)",
          run: () => setRecording(false),
        },
      },
    };
  },
});
