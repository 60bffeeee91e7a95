/**
 * The toolbar's Record button (issue 16, item 5): a dialog picks block outputs (the acquisition
 * blocks' by default) and a format; while the session recording runs the button shows a red dot
 * and the file, duration, size and samples written; Stop finishes the file (a download in the
 * browser build, where the engine keeps it in memory).
 */
import { useEffect, useId, useMemo, useRef, useState, type RefObject } from "react";
import type { GraphInfo, RecordingFormatName, RecordingStatus } from "../../engine/protocol";
import { useEngine, useEngineInfo } from "../client/hooks";

/** Blocks whose outputs are recorded unless the user picks others: what acquires the signals. */
const ACQUISITION = new Set(["Devices", "Sources"]);

const FORMATS: { value: RecordingFormatName; label: string; hint: string }[] = [
  { value: "xdf", label: "XDF", hint: "LabRecorder's format: every output a stream, exact values" },
  { value: "edf", label: "EDF+", hint: "16-bit clinical standard (EDFbrowser, MNE, EEGLAB)" },
  { value: "bdf", label: "BDF+", hint: "24-bit EDF+ (BioSemi)" },
];

const STATE_WORDS: Record<RecordingStatus["state"], string> = {
  recording: "Recording",
  finished: "Recorded",
  failed: "Recording failed",
};

export interface RecordableOutput {
  /** "Emg", or "Myo.imu" for a port other than the default. */
  key: string;
  block: string;
  port: string;
  detail: string;
  acquisition: boolean;
}

/** Every output that carries values (timers' ticks do not). */
export function recordableOutputs(graph: GraphInfo | undefined): RecordableOutput[] {
  const out: RecordableOutput[] = [];
  for (const b of graph?.blocks ?? []) {
    if (b.timer) continue;
    b.outputs.forEach((o, i) => {
      const values = o.shape.rows * o.shape.cols;
      if (values === 0) return;
      const rate = b.desiredRate > 0 ? `${+b.desiredRate.toFixed(2)} Hz` : "events";
      out.push({
        key: i === 0 ? b.name : `${b.name}.${o.name}`,
        block: b.name,
        port: o.name,
        detail: `${b.type}, ${values} value${values === 1 ? "" : "s"}, ${rate}`,
        acquisition: ACQUISITION.has(b.category),
      });
    });
  }
  return out;
}

/** 812 B, 3.4 kB, 12.0 MB, 1.25 GB. */
export function formatSize(n: number): string {
  if (n < 1000) return `${n} B`;
  if (n < 1e6) return `${(n / 1e3).toFixed(1)} kB`;
  if (n < 1e9) return `${(n / 1e6).toFixed(1)} MB`;
  return `${(n / 1e9).toFixed(2)} GB`;
}

/** "rec.xdf · 12.3 s · 1.2 MB · 24 600 samples" (the file's name, not its folder). */
export function recordingSummary(r: RecordingStatus): string {
  const name = r.file.split(/[/\\]/).pop() ?? r.file;
  const samples = r.samples.toLocaleString("en").replaceAll(",", "\u202f");
  return `${name} · ${r.duration.toFixed(1)} s · ${formatSize(r.bytes)} · ${samples} samples`;
}

/** The outputs to record and the format, as picked in the dialog (acquisition outputs first). */
function useRecordChoice(graph: GraphInfo | undefined) {
  const outputs = useMemo(() => recordableOutputs(graph), [graph]);
  const [chosen, setChosen] = useState<Set<string>>(
    () => new Set(outputs.filter((o) => o.acquisition).map((o) => o.key)),
  );
  const [format, setFormat] = useState<RecordingFormatName>("xdf");
  return { outputs, chosen, setChosen, format, setFormat };
}

/** Opens the dialog as a modal once it is mounted. */
function useShowModal(ref: RefObject<HTMLDialogElement | null>): void {
  useEffect(() => {
    const d = ref.current;
    if (d && !d.open) d.showModal();
  }, []);
}

/** A copy of `chosen` with `key` added (`on`) or removed. */
function toggled(chosen: Set<string>, key: string, on: boolean): Set<string> {
  const next = new Set(chosen);
  if (on) next.add(key);
  else next.delete(key);
  return next;
}

/** A checkbox for every recordable output (or why there is none). */
function OutputChoices({
  outputs,
  chosen,
  onToggle,
}: {
  outputs: RecordableOutput[];
  chosen: Set<string>;
  onToggle(key: string, on: boolean): void;
}) {
  return (
    <fieldset className="record-dialog__outputs">
      <legend>Outputs</legend>
      {outputs.length === 0 ? <p>This pipeline has no output to record.</p> : null}
      {outputs.map((o) => (
        <label key={o.key} className="record-dialog__output">
          <input
            type="checkbox"
            checked={chosen.has(o.key)}
            onChange={(e) => onToggle(o.key, e.target.checked)}
          />
          <span className="record-dialog__name">{o.key}</span>
          <span className="record-dialog__detail">{o.detail}</span>
        </label>
      ))}
    </fieldset>
  );
}

/** A radio button for every file format. */
function FormatChoices({
  name,
  format,
  onFormat,
}: {
  name: string;
  format: RecordingFormatName;
  onFormat(format: RecordingFormatName): void;
}) {
  return (
    <fieldset className="record-dialog__formats">
      <legend>Format</legend>
      {FORMATS.map((f) => (
        <label key={f.value} title={f.hint}>
          <input
            type="radio"
            name={name}
            value={f.value}
            checked={format === f.value}
            onChange={() => onFormat(f.value)}
          />
          {f.label}
        </label>
      ))}
    </fieldset>
  );
}

/** Where the file goes: downloaded (engine in the page) or written as it records. */
function RecordWhere({ inPage }: { inPage: boolean }) {
  return (
    <p className="record-dialog__where">
      {inPage
        ? "Kept in memory while it records, downloaded when you stop it."
        : "Written to recordings/ in the data folder (else the pipeline's folder) as it records."}
    </p>
  );
}

/** Cancel, and Start recording (disabled while nothing is picked). */
function DialogButtons({ canStart, onClose }: { canStart: boolean; onClose(): void }) {
  return (
    <div className="record-dialog__buttons">
      <button type="button" onClick={onClose}>
        Cancel
      </button>
      <button type="submit" className="primary" disabled={!canStart}>
        Start recording
      </button>
    </div>
  );
}

/** The Record dialog: pick outputs and a format, then Start recording (or Cancel). */
function RecordDialog({
  graph,
  onStart,
  onClose,
}: {
  graph: GraphInfo | undefined;
  onStart(outputs: RecordableOutput[], format: RecordingFormatName): void;
  onClose(): void;
}) {
  const ref = useRef<HTMLDialogElement>(null);
  // The browser build's engine runs in the page and cannot write files.
  const inPage = useEngineInfo().engine.startsWith("browser");
  const { outputs, chosen, setChosen, format, setFormat } = useRecordChoice(graph);
  const id = useId();
  useShowModal(ref);
  const toggle = (key: string, on: boolean): void => setChosen((s) => toggled(s, key, on));
  const picked = outputs.filter((o) => chosen.has(o.key));
  return (
    <dialog
      ref={ref}
      className="record-dialog"
      aria-labelledby={`${id}-title`}
      onClose={onClose}
      onCancel={onClose}
    >
      <form
        method="dialog"
        onSubmit={(e) => {
          e.preventDefault();
          if (picked.length > 0) onStart(picked, format);
        }}
      >
        <h2 id={`${id}-title`}>Record</h2>
        <OutputChoices outputs={outputs} chosen={chosen} onToggle={toggle} />
        <FormatChoices name={`${id}-format`} format={format} onFormat={setFormat} />
        <RecordWhere inPage={inPage} />
        <DialogButtons canStart={picked.length > 0} onClose={onClose} />
      </form>
    </dialog>
  );
}

export function RecordControl({
  graph,
  running,
  notify,
}: {
  graph: GraphInfo | undefined;
  running: boolean;
  notify(message: string, level?: "info" | "error"): void;
}) {
  const client = useEngine();
  const [status, setStatus] = useState<RecordingStatus | undefined>(client.recording);
  const [dialog, setDialog] = useState(false);
  useEffect(() => client.onRecording(setStatus), [client]);
  const recording = status?.state === "recording";

  const start = (outputs: RecordableOutput[], format: RecordingFormatName): void => {
    setDialog(false);
    void client
      .recordStart(
        outputs.map((o) => ({ block: o.block, port: o.port })),
        format,
      )
      .then((r) => notify(r.message ?? "recording", r.ok ? "info" : "error"));
  };
  const stop = (): void => {
    void client.recordStop().then((r) => notify(r.message ?? "stopped", r.ok ? "info" : "error"));
  };

  return (
    <>
      {recording ? (
        <button
          type="button"
          className="record-button is-recording"
          onClick={stop}
          title={`Recording ${status.outputs.join(", ")} to ${status.file}: press to finish the file`}
        >
          <span className="record-button__dot" aria-hidden="true" />
          Stop recording
        </button>
      ) : (
        <button
          type="button"
          className="record-button"
          onClick={() => setDialog(true)}
          disabled={!running}
          title={
            running
              ? "Record block outputs into an XDF, EDF+ or BDF+ file"
              : "Start the pipeline to record it"
          }
        >
          <span className="record-button__dot" aria-hidden="true" />
          Record…
        </button>
      )}
      {status ? (
        <span className={`record-status state-${status.state}`} title={status.error ?? status.file}>
          <span className="sr-only">{STATE_WORDS[status.state]}: </span>
          {recordingSummary(status)}
          {status.state === "failed" ? ` · failed: ${status.error ?? ""}` : ""}
        </span>
      ) : null}
      {dialog ? (
        <RecordDialog graph={graph} onStart={start} onClose={() => setDialog(false)} />
      ) : null}
    </>
  );
}
