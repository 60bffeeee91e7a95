/**
 * A block's params as a form generated from its JSON Schema (`BlockInfo.paramsSchema`). Live
 * params (`BlockInfo.live`) are editable whenever a pipeline is loaded: a valid change is sent
 * with `onSet` (Enter, leaving the field or picking an option; groups have Apply), and the
 * engine's reply is shown next to the field, a rejection included. Invalid input is shown next to
 * the field and never sent. Other params are fixed once the pipeline is instantiated: read-only,
 * with a hint (or editable through `onEditStatic` while not running, when the host offers it).
 * The values shown are the engine's (`block.params`, kept current by the caller); a live param
 * whose value is not the file's (`block.fileParams`) is marked "changed since loaded", and the
 * form offers to write the live values back to the file (`onWriteBack`).
 */
import { useMemo, type ReactNode } from "react";
import type { BlockInfo, EngineState } from "../../engine/protocol";
import { changedParams } from "../editor/live-values";
import { ParamRow } from "./params-row";
import { describeParams, type Field, type JsonSchema } from "./schema";
import "./forms.css";

export interface SetResult {
  ok: boolean;
  message?: string;
}

export interface ParamsFormProps {
  block: BlockInfo;
  engineState: EngineState;
  /** Sends a live param to the engine (EngineClient.setParam) and resolves with its reply. */
  onSet: (param: string, value: unknown) => Promise<SetResult>;
  /**
   * Optional: changes a param that is not live while the pipeline is not running (e.g. the shell
   * edits the pipeline file and reloads it). Without it such params are read-only.
   */
  onEditStatic?: (param: string, value: unknown) => Promise<SetResult>;
  /** Writes every live value that is not the file's back into the file (the shell's action). */
  onWriteBack?: () => void;
}

export function ParamsForm({
  block,
  engineState,
  onSet,
  onEditStatic,
  onWriteBack,
}: ParamsFormProps): ReactNode {
  const root = (block.paramsSchema ?? {}) as JsonSchema;
  const form = useMemo(() => describeParams(root), [root]);
  const live = new Set(block.live);
  const running = engineState === "running";
  const loaded = engineState !== "empty";
  if (form.fields.length === 0) {
    return <p className="mf-empty">{block.type} has no params.</p>;
  }
  const liveFields = form.fields.filter((f) => live.has(f.name));
  const fixedFields = form.fields.filter((f) => !live.has(f.name));
  const staticEditable = !running && loaded && onEditStatic !== undefined;
  const changed = new Set(changedParams(block));
  const row = (f: Field, isLive: boolean): ReactNode => (
    <ParamRow
      key={`${block.name}.${f.name}`}
      field={f}
      root={root}
      initial={block.params[f.name]}
      changed={changed.has(f.name)}
      fileValue={block.fileParams?.[f.name]}
      live={isLive}
      editable={isLive ? loaded : staticEditable}
      running={running}
      send={isLive ? onSet : onEditStatic}
    />
  );
  return (
    <form
      className="mf-form"
      onSubmit={(e) => e.preventDefault()}
      aria-label={`${block.name} params`}
      data-changed={changed.size}
    >
      {changed.size > 0 && <ChangedNote count={changed.size} onWriteBack={onWriteBack} />}
      {liveFields.length > 0 && (
        <section className="mf-group" aria-label="live params">
          <h4 className="mf-group-title">
            Live{" "}
            <span className="mf-muted">— changes apply at once (Enter, or leave the field)</span>
          </h4>
          {liveFields.map((f) => row(f, true))}
        </section>
      )}
      {fixedFields.length > 0 && (
        <section className="mf-group" aria-label="fixed params">
          <h4 className="mf-group-title">
            {liveFields.length ? "Fixed" : "Params"}{" "}
            <span className="mf-muted">{fixedHint(staticEditable, running)}</span>
          </h4>
          {fixedFields.map((f) => row(f, false))}
        </section>
      )}
    </form>
  );
}

/** How the fixed params change, after the group's title. */
function fixedHint(staticEditable: boolean, running: boolean): string {
  return staticEditable
    ? "— applied by reloading the pipeline"
    : running
      ? "— fixed while running: change them in the pipeline file and reload"
      : "— set when the pipeline loads: change them in the pipeline file";
}

/** The block's "changed since loaded" line, with the write-back action when offered. */
function ChangedNote({
  count,
  onWriteBack,
}: {
  count: number;
  onWriteBack: (() => void) | undefined;
}): ReactNode {
  return (
    <p className="mf-changed-note" role="note">
      <span className="mf-badge mf-badge-changed">changed since loaded</span>{" "}
      {count === 1 ? "1 live value differs" : `${count} live values differ`} from the file.{" "}
      {onWriteBack && (
        <button type="button" className="mf-link" onClick={onWriteBack}>
          Write live values back to the file
        </button>
      )}
    </p>
  );
}
