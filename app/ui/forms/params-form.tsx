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
import { useEffect, useId, useMemo, useRef, useState, type ReactNode } from "react";
import type { BlockInfo, EngineState } from "../../engine/protocol";
import { changedParams } from "../editor/live-values";
import { FieldEditor, isOneLine } from "./field-editors";
import {
  deepEqual,
  describeParams,
  describeType,
  hasInvalid,
  summarize,
  validate,
  type Field,
  type Issue,
  type JsonSchema,
} from "./schema";
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
            <span className="mf-muted">
              {staticEditable
                ? "— applied by reloading the pipeline"
                : running
                  ? "— fixed while running: change them in the pipeline file and reload"
                  : "— set when the pipeline loads: change them in the pipeline file"}
            </span>
          </h4>
          {fixedFields.map((f) => row(f, false))}
        </section>
      )}
    </form>
  );
}

type Reply =
  | { kind: "idle" }
  | { kind: "pending" }
  | { kind: "ok"; message: string }
  | { kind: "error"; message: string };

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

interface RowProps {
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

function ParamRow({
  field,
  root,
  initial,
  changed,
  fileValue,
  live,
  editable,
  running,
  send,
}: RowProps): ReactNode {
  const name = field.name;
  const [current, setCurrent] = useState<unknown>(initial);
  const [draft, setDraft] = useState<unknown>(initial);
  const [reply, setReply] = useState<Reply>({ kind: "idle" });
  const mounted = useRef(true);
  const inFlight = useRef<unknown>(undefined);
  useEffect(() => {
    mounted.current = true;
    return () => {
      mounted.current = false;
    };
  }, []);
  // The engine's value changed (another client, a reload): shown at once, unless being edited.
  const shownInitial = useRef(initial);
  useEffect(() => {
    const before = shownInitial.current;
    shownInitial.current = initial;
    if (deepEqual(before, initial)) return;
    setCurrent(initial);
    setDraft((d: unknown) => (deepEqual(d, before) ? initial : d));
    setReply((r) => (r.kind === "pending" ? r : { kind: "idle" }));
  }, [initial]);

  const issues = useMemo(() => {
    const is: Issue[] = validate(field.schema, draft, root);
    if (draft === undefined && field.required) is.unshift({ path: [], message: "required" });
    return is;
  }, [field, draft, root]);
  const dirty = !deepEqual(draft, current);
  const valid = issues.length === 0 && !hasInvalid(draft);
  const id = useId();
  const oneLine = isOneLine(field);

  const commit = async (value: unknown): Promise<void> => {
    if (!editable || !send) return;
    const is = validate(field.schema, value, root);
    if (is.length || hasInvalid(value) || (value === undefined && field.required)) return;
    if (
      deepEqual(value, current) ||
      (inFlight.current !== undefined && deepEqual(value, inFlight.current))
    )
      return;
    inFlight.current = value;
    setReply({ kind: "pending" });
    const r = await send(name, value);
    inFlight.current = undefined;
    if (!mounted.current) return;
    if (r.ok) {
      setCurrent(value);
      setReply({ kind: "ok", message: r.message ?? "applied" });
    } else {
      setReply({ kind: "error", message: r.message ?? "rejected by the engine" });
    }
  };
  const revert = (): void => {
    setDraft(current);
    setReply({ kind: "idle" });
  };

  const isDefault = field.hasDefault && deepEqual(current, field.default);
  return (
    <div
      className={`mf-param${live ? " mf-live" : ""}${editable ? "" : " mf-readonly"}`}
      data-param={name}
      data-live={live ? "true" : "false"}
      data-changed={changed ? "true" : "false"}
    >
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
          <span className={`mf-default${isDefault ? "" : " mf-changed"}`}>
            default {summarize(field.default, 40)}
            {!isDefault && editable && (
              <button
                type="button"
                className="mf-link"
                onClick={() => {
                  setDraft(field.default);
                  if (oneLine) void commit(field.default);
                }}
              >
                reset
              </button>
            )}
          </span>
        )}
      </div>
      <div className="mf-control">
        {editable ? (
          <FieldEditor
            field={field}
            id={id}
            label={name}
            value={draft}
            disabled={false}
            issues={issues}
            onChange={(v) => {
              setDraft(v);
              if (reply.kind !== "pending") setReply({ kind: "idle" });
            }}
            onCommit={oneLine ? (v) => void commit(v) : undefined}
            onRevert={revert}
          />
        ) : (
          <ReadOnlyValue value={current} field={field} running={running} live={live} />
        )}
        {editable && !oneLine && dirty && (
          <span className="mf-actions">
            <button
              type="button"
              className="mf-apply"
              disabled={!valid || reply.kind === "pending"}
              onClick={() => void commit(draft)}
            >
              Apply
            </button>
            <button type="button" onClick={revert}>
              Revert
            </button>
          </span>
        )}
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
