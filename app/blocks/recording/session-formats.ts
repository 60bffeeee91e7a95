/**
 * The file formats of session recordings (the UI's Record button, app/engine/recording/): XDF,
 * EDF+ and BDF+, written by the same code as the XdfRecorder and EdfRecorder blocks. The outputs
 * chosen in the UI are described to the planners as a recorder block's inputs would be, so a
 * session recording's streams, labels, units, markers and record duration are those the blocks
 * would choose. Injected into EngineSession by its hosts (SessionPlatform.recordingFormats).
 */
import type { BlockContext, FileWriteHandle, Frame, InputInfo } from "../../engine";
import type {
  RecordedOutput,
  RecordingFormat,
  RecordingFormats,
  RecordingWriter,
} from "../../engine/recording/format";
import { lagRecords, markerText, changed } from "./edf-recorder";
import { edfParams, resolveEdfSetup, type EdfSetup, type MarkerSlot } from "./edf-setup";
import { EdfStream } from "./edf-stream";
import type { EdfFormat } from "./edf-writer";
import { XdfFileWriter } from "./xdf-file";
import { planStreams } from "./xdf-streams";
import { MarkerStream, NumericStream } from "./xdf-writer";

/** The name planners see for the recorder (stream source ids: MOSAIC/Record/<output>). */
const RECORDER_NAME = "Record";

/** The outputs as a recorder block's inputs. */
function asInputs(outputs: readonly RecordedOutput[]): InputInfo[] {
  return outputs.map((o, index) => ({
    index,
    source: o.source,
    block: o.block,
    port: o.port,
    type: o.blockType,
    shape: o.shape,
    rate: o.rate,
    isTimer: false,
    subscribed: true,
    ...(o.meta ? { meta: o.meta } : {}),
  }));
}

/**
 * What the planners (planStreams, resolveEdfSetup) read of a block's context: its name, type and
 * inputs. Anything else they might read one day fails loudly instead of silently.
 */
function plannerContext(type: string, inputs: readonly InputInfo[]): BlockContext {
  const known: Record<string, unknown> = { name: RECORDER_NAME, type, inputs };
  return new Proxy(known, {
    get(target, key) {
      if (typeof key === "string" && Object.hasOwn(target, key)) return target[key];
      throw new Error(`a session recording cannot plan with ctx.${String(key)}`);
    },
  }) as unknown as BlockContext;
}

// ---------------------------------------------------------------------------------------------
// XDF

/** Each event as one marker: its values in shortest round-trip form, joined by commas. */
function appendMarkers(m: MarkerStream, f: Frame): void {
  const s = f.stride;
  for (let i = 0; i < f.n; i++) {
    let text = "";
    for (let k = 0; k < s; k++) text += (k > 0 ? "," : "") + String(f.v[i * s + k]);
    m.append(f.t[i]!, text);
  }
}

function isoTime(t: number): string {
  const d = new Date(t * 1000);
  return Number.isFinite(d.getTime()) ? d.toISOString() : "";
}

class XdfSessionWriter implements RecordingWriter {
  private readonly numeric: (NumericStream | null)[];
  private readonly markers: (MarkerStream | null)[];
  constructor(private readonly xdf: XdfFileWriter) {
    this.numeric = xdf.streams.map((s) => (s instanceof NumericStream ? s : null));
    this.markers = xdf.streams.map((s) => (s instanceof MarkerStream ? s : null));
  }
  append(i: number, f: Frame): void {
    const num = this.numeric[i];
    if (num) num.append(f.t, f.v, f.n, f.stride);
    else appendMarkers(this.markers[i]!, f);
  }
  flush(now: number): void {
    this.xdf.flush(now);
  }
  close(now: number): void {
    this.xdf.close(now);
  }
  abandon(): void {
    this.xdf.abandon();
  }
  get samplesWritten(): number {
    return this.xdf.samplesWritten;
  }
}

/**
 * XDF as the XdfRecorder writes it, every signal in double64 (values exact: a recording replays
 * bit for bit), event outputs as string marker streams.
 */
export const xdfSessionFormat: RecordingFormat = {
  extension: "xdf",
  mime: "application/octet-stream",
  plan(outputs: readonly RecordedOutput[]) {
    const planned = planStreams(plannerContext("XdfRecorder", asInputs(outputs)), "double64", {});
    const expected = planned.map((s) => Math.ceil(Math.max(s.nominalRate, 1) * 0.2));
    return {
      open(file: FileWriteHandle, now: number): RecordingWriter {
        const infos = planned.map((s, i) => ({
          ...s,
          createdAt: now,
          uid: `session-${i + 1}-${now}`,
        }));
        return new XdfSessionWriter(new XdfFileWriter(file, infos, now, isoTime(now), expected));
      },
    };
  },
};

// ---------------------------------------------------------------------------------------------
// EDF+ / BDF+

class EdfSessionWriter implements RecordingWriter {
  private readonly signalOf: Int32Array;
  private readonly markerOf: Map<number, MarkerSlot>;
  private readonly lastMarker: { v: Float64Array | null }[];
  private readonly stream: EdfStream;
  /** Samples (events) one data record holds, all signal inputs together. */
  private readonly eventsPerRecord: number;

  constructor(
    private readonly file: FileWriteHandle,
    private readonly setup: EdfSetup,
  ) {
    this.signalOf = new Int32Array(setup.signals.length + setup.markers.length).fill(-1);
    setup.signals.forEach((s, k) => (this.signalOf[s.index] = k));
    this.markerOf = new Map(setup.markers.map((m) => [m.index, m]));
    this.lastMarker = setup.markers.map(() => ({ v: null }));
    this.eventsPerRecord = setup.streamInputs.reduce((a, s, k) => {
      return a + s.samplesPerRecord / setup.signals[k]!.rows;
    }, 0);
    this.stream = new EdfStream(
      {
        format: setup.format,
        inputs: setup.streamInputs,
        recordUs: setup.duration.us,
        recordText: setup.duration.text,
        annotationBytes: setup.annotationBytes,
        patient: "X X X X",
        recording: "X X MOSAIC",
        maxLagRecords: lagRecords(setup.duration.us),
      },
      file,
    );
  }

  append(i: number, f: Frame): void {
    if (f.n === 0) return;
    const k = this.signalOf[i]!;
    if (k >= 0) {
      this.stream.append(k, f.t[0]!, f.v, f.n * this.setup.signals[k]!.rows);
      return;
    }
    const m = this.markerOf.get(i)!;
    const last = this.lastMarker[this.setup.markers.indexOf(m)]!;
    for (let e = 0; e < f.n; e++) {
      if (m.onChange && !changed(f, e, last)) continue;
      this.stream.annotate(f.t[e]!, markerText(m.source, f, e));
    }
  }

  /** Records go out as soon as every input has filled them: nothing waits here. */
  flush(): void {}

  close(): void {
    try {
      this.file.sync();
    } finally {
      this.file.close();
    }
  }

  abandon(): void {
    try {
      this.file.close();
    } catch {
      // the file already failed; its first error is the one reported
    }
  }

  get samplesWritten(): number {
    return Math.round(this.stream.counts.records * this.eventsPerRecord);
  }
}

function edfFormat(format: EdfFormat): RecordingFormat {
  return {
    extension: format,
    mime: "application/octet-stream",
    plan(outputs: readonly RecordedOutput[]) {
      const p = edfParams.parse({ Format: format });
      const setup = resolveEdfSetup(plannerContext("EdfRecorder", asInputs(outputs)), p);
      return { open: (file: FileWriteHandle) => new EdfSessionWriter(file, setup) };
    },
  };
}

export const edfSessionFormat = edfFormat("edf");
export const bdfSessionFormat = edfFormat("bdf");

/** Every format a session recording can write. */
export const sessionRecordingFormats: RecordingFormats = {
  xdf: xdfSessionFormat,
  edf: edfSessionFormat,
  bdf: bdfSessionFormat,
};
