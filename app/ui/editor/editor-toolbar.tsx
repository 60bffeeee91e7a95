/**
 * The editor's bar: new from an example, Undo/Redo, Duplicate/Delete, Take live values, the
 * state of the text (problems, not applied, applied), Apply, Save… and Done.
 */
import type { ReactNode } from "react";
import { TakeLiveValues } from "./live-values-bar";
import type { EditorModel } from "./use-editor";
import type { Notify } from "./use-editor-edits";

export interface TemplateEntry {
  file: string;
  title: string;
}

/** Where the text stands. */
export interface EditorStatus {
  /** An Apply is under way (the pipeline restarts). */
  applying: boolean;
  /** How many errors the text has. */
  errors: number;
  /** The text on screen is being checked. */
  checking: boolean;
  /** The text differs from the one that runs. */
  dirty: boolean;
  /** A pipeline is loaded in the engine. */
  loaded: boolean;
}

export interface EditorToolbarProps {
  ed: EditorModel;
  templates: readonly TemplateEntry[];
  status: EditorStatus;
  /** A block is selected. */
  blockSelected: boolean;
  /** A block or a connection is selected. */
  anySelected: boolean;
  onPickTemplate(file: string): Promise<void>;
  onDuplicate(): void;
  onDelete(): void;
  onNotify: Notify;
  /** Live values were taken into the text. */
  onTaken(): void;
  onApply(): Promise<void>;
  onSave(): void;
  onClose(): void;
}

function TemplatePicker({
  templates,
  onPick,
}: {
  templates: readonly TemplateEntry[];
  onPick(file: string): Promise<void>;
}): ReactNode {
  return (
    <label className="editor__template">
      <span>New from</span>
      <select
        value=""
        onChange={(e) => void onPick(e.target.value)}
        aria-label="New pipeline from an example"
      >
        <option value="">example…</option>
        <option value="(empty)">Empty pipeline</option>
        {templates.map((t) => (
          <option key={t.file} value={t.file}>
            {t.file.replace(/^pipelines\//, "")}
          </option>
        ))}
      </select>
    </label>
  );
}

function EditButtons(props: EditorToolbarProps): ReactNode {
  const { ed } = props;
  return (
    <>
      <button type="button" onClick={ed.undo} disabled={!ed.canUndo} title="Undo (Ctrl+Z)">
        Undo
      </button>
      <button type="button" onClick={ed.redo} disabled={!ed.canRedo} title="Redo (Ctrl+Shift+Z)">
        Redo
      </button>
      <button
        type="button"
        onClick={props.onDuplicate}
        disabled={!props.blockSelected}
        title="Duplicate the block (Ctrl+D)"
      >
        Duplicate
      </button>
      <button
        type="button"
        onClick={props.onDelete}
        disabled={!props.anySelected}
        title="Delete the selected block or connection (Delete)"
      >
        Delete
      </button>
    </>
  );
}

function stateText({ applying, errors, dirty }: EditorStatus): string {
  if (applying) return "restarting…";
  if (errors > 0) return `${errors} problem${errors === 1 ? "" : "s"}: fix to apply or save`;
  return dirty ? "changes not applied" : "applied";
}

function saveTitle({ errors, checking }: EditorStatus): string {
  if (errors > 0) return "Fix the problems first";
  return checking ? "The text is being checked" : "Download the pipeline file";
}

function FileButtons(props: EditorToolbarProps): ReactNode {
  const s = props.status;
  const nothingToApply = props.ed.blocks.length === 0 || (!s.dirty && s.loaded);
  return (
    <>
      <button
        type="button"
        className="primary"
        onClick={() => void props.onApply()}
        disabled={s.applying || s.errors > 0 || s.checking || nothingToApply}
        title="Load the edited pipeline and start it (a short restart)"
      >
        Apply
      </button>
      <button
        type="button"
        onClick={props.onSave}
        disabled={s.errors > 0 || s.checking}
        title={saveTitle(s)}
      >
        Save…
      </button>
      <button type="button" onClick={props.onClose} title="Leave edit mode">
        Done
      </button>
    </>
  );
}

export function EditorToolbar(props: EditorToolbarProps): ReactNode {
  return (
    <div className="editor__bar" role="toolbar" aria-label="Editor">
      <TemplatePicker templates={props.templates} onPick={props.onPickTemplate} />
      <EditButtons {...props} />
      <TakeLiveValues ed={props.ed} onNotify={props.onNotify} onTaken={props.onTaken} />
      <span className="toolbar__spacer" />
      <span className="editor__state" role="status" aria-live="polite">
        {stateText(props.status)}
      </span>
      <FileButtons {...props} />
    </div>
  );
}
