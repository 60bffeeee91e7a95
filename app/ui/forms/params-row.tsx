/**
 * One param of ParamsForm: its head (name, badges, type, default with reset), its editor (or its
 * value, read-only), Apply/Revert for multi-line editors and the engine's reply.
 */
import { useId, type ReactNode } from "react";
import type { SetResult } from "./params-form";
import { useParamDraft, type ParamDraft, type Reply } from "./params-row-state";
import { FieldEditor, isOneLine } from "./field-editors";
import {
  deepEqual,
  describeType,
  hasInvalid,
  summarize,
  type Field,
  type JsonSchema,
} from "./schema";

export interface RowProps {
  field: Field;
  root: JsonSchema;
  /** The engine's value. */
  initial: unknown;
  /** A live value other than the file's (`fileValue`). */
  changed: boolean;
  fileValue: unknown;
  live: boolean;
  editable: boolean;
  running: boolean;
  send?: (param: string, value: unknown) => Promise<SetResult>;
}

export function ParamRow(props: RowProps): ReactNode {
  const { field, root, initial, changed, live, editable, running, send } = props;
  const name = field.name;
  const state = useParamDraft(field, root, initial, editable, send);
  const { current, draft, reply } = state;
  const dirty = !deepEqual(draft, current);
  const valid = state.issues.length === 0 && !hasInvalid(draft);
  const id = useId();
  const oneLine = isOneLine(field);
  return (
    <div
      className={`mf-param${live ? " mf-live" : ""}${editable ? "" : " mf-readonly"}`}
      data-param={name}
      data-live={live ? "true" : "false"}
      data-changed={changed ? "true" : "false"}
    >
      <ParamHead {...props} id={id} oneLine={oneLine} state={state} />
      <div className="mf-control">
        {editable ? (
          <ParamEditor field={field} id={id} oneLine={oneLine} state={state} />
        ) : (
          <ReadOnlyValue value={current} field={field} running={running} live={live} />
        )}
        {editable && !oneLine && dirty && <ApplyRevert valid={valid} state={state} />}
      </div>
      <ReplyLine reply={reply} dirty={dirty} valid={valid} oneLine={oneLine} />
      {field.description && (
        <p className="mf-help" title={editable ? undefined : field.description}>
          {field.description}
        </p>
      )}
    </div>
  );
}

/** The row's head: name (required mark), live and changed badges, type, default with reset. */
function ParamHead({
  field,
  changed,
  fileValue,
  live,
  editable,
  id,
  oneLine,
  state,
}: RowProps & { id: string; oneLine: boolean; state: ParamDraft }): ReactNode {
  const name = field.name;
  return (
    <div className="mf-head">
      <label className="mf-label" htmlFor={editable ? id : undefined}>
        {name}
        {field.required && (
          <span className="mf-req" title="required" aria-label="required">
            *
          </span>
        )}
      </label>
      {live && <span className="mf-badge mf-badge-live">live</span>}
      {changed && (
        <span
          className="mf-badge mf-badge-changed"
          data-changed-param={name}
          title={`Changed since the pipeline was loaded: the file says ${summarize(fileValue, 200)}`}
        >
          changed · file: {summarize(fileValue, 24)}
        </span>
      )}
      <span className="mf-type">{describeType(field)}</span>
      {field.hasDefault && (
        <DefaultNote field={field} editable={editable} oneLine={oneLine} state={state} />
      )}
    </div>
  );
}

/** The param's default, marked when the value is another, with reset (while editable). */
function DefaultNote({
  field,
  editable,
  oneLine,
  state,
}: {
  field: Field;
  editable: boolean;
  oneLine: boolean;
  state: ParamDraft;
}): ReactNode {
  const isDefault = field.hasDefault && deepEqual(state.current, field.default);
  return (
    <span className={`mf-default${isDefault ? "" : " mf-changed"}`}>
      default {summarize(field.default, 40)}
      {!isDefault && editable && (
        <button
          type="button"
          className="mf-link"
          onClick={() => {
            state.setDraft(field.default);
            if (oneLine) void state.commit(field.default);
          }}
        >
          reset
        </button>
      )}
    </span>
  );
}

/** The field's editor: one-line editors send on Enter or leaving the field, Esc reverts. */
function ParamEditor({
  field,
  id,
  oneLine,
  state,
}: {
  field: Field;
  id: string;
  oneLine: boolean;
  state: ParamDraft;
}): ReactNode {
  return (
    <FieldEditor
      field={field}
      id={id}
      label={field.name}
      value={state.draft}
      disabled={false}
      issues={state.issues}
      onChange={(v) => {
        state.setDraft(v);
        if (state.reply.kind !== "pending") state.setReply({ kind: "idle" });
      }}
      onCommit={oneLine ? (v) => void state.commit(v) : undefined}
      onRevert={state.revert}
    />
  );
}

/** Apply and Revert of a multi-line editor with a change. */
function ApplyRevert({ valid, state }: { valid: boolean; state: ParamDraft }): ReactNode {
  return (
    <span className="mf-actions">
      <button
        type="button"
        className="mf-apply"
        disabled={!valid || state.reply.kind === "pending"}
        onClick={() => void state.commit(state.draft)}
      >
        Apply
      </button>
      <button type="button" onClick={state.revert}>
        Revert
      </button>
    </span>
  );
}

function ReplyLine({
  reply,
  dirty,
  valid,
  oneLine,
}: {
  reply: Reply;
  dirty: boolean;
  valid: boolean;
  oneLine: boolean;
}): ReactNode {
  if (reply.kind === "pending") return <p className="mf-reply mf-pending">sending…</p>;
  if (reply.kind === "error")
    return (
      <p className="mf-reply mf-rejected" role="alert">
        engine: {reply.message}
      </p>
    );
  if (reply.kind === "ok" && !dirty)
    return (
      <p className="mf-reply mf-ok">
        ✓ applied <span className="mf-muted">— engine: {reply.message}</span>
      </p>
    );
  if (dirty && valid && oneLine)
    return <p className="mf-reply mf-muted">press Enter to apply, Esc to revert</p>;
  return null;
}

function ReadOnlyValue({
  value,
  field,
  running,
  live,
}: {
  value: unknown;
  field: Field;
  running: boolean;
  live: boolean;
}): ReactNode {
  const text = summarize(value, 100_000);
  const short = summarize(value, 90);
  const shown =
    value === undefined
      ? field.hasDefault
        ? `${summarize(field.default, 60)} (default)`
        : "not set"
      : short;
  const why = live
    ? "no pipeline is loaded"
    : running
      ? "fixed while running"
      : "set when the pipeline loads";
  return (
    <span className="mf-ro" title={why}>
      <output className="mf-ro-value">{shown}</output>
      {text.length > short.length && (
        <details className="mf-ro-more">
          <summary>all</summary>
          <pre>{text}</pre>
        </details>
      )}
      {live && <span className="mf-ro-hint">({why})</span>}
    </span>
  );
}
