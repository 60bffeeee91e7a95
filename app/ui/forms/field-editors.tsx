/**
 * Editors for the fields of ./schema.ts, recursive for objects, lists and mappings. An editor
 * shows a value, reports every change with `onChange` (text that does not parse is reported as an
 * InvalidText, so it can be shown and never sent), and shows the issues found below its path.
 * One-line editors at the top level also report `onCommit` (Enter, leaving the field, picking an
 * option); Escape asks to revert.
 */
import { useEffect, useId, useRef, useState, type KeyboardEvent, type ReactNode } from "react";
import {
  InvalidText,
  TEXT_KINDS,
  describeType,
  emptyValue,
  formatText,
  issueText,
  issuesUnder,
  parseText,
  summarize,
  type EnumField,
  type Field,
  type Issue,
  type ListField,
  type ObjectField,
  type RecordField,
} from "./schema";

export interface EditorProps {
  field: Field;
  value: unknown;
  onChange: (v: unknown) => void;
  /** Issues at or below this editor, paths relative to it. */
  issues: Issue[];
  disabled: boolean;
  /** Accessible name (the param or key name). */
  label: string;
  id?: string;
  onCommit?: (v: unknown) => void;
  onRevert?: () => void;
}

/** Whether the editor of this field is one input (commits on Enter / change) or a group. */
export const isOneLine = (f: Field): boolean =>
  (TEXT_KINDS.has(f.kind) && f.kind !== "matrix" && f.kind !== "json") ||
  f.kind === "boolean" ||
  f.kind === "enum";

export function FieldEditor(props: EditorProps): ReactNode {
  switch (props.field.kind) {
    case "boolean":
      return <BooleanEditor {...props} />;
    case "enum":
      return <EnumEditor {...props} field={props.field} />;
    case "object":
      return <ObjectEditor {...props} field={props.field} />;
    case "list":
      return <ListEditor {...props} field={props.field} />;
    case "record":
      return <RecordEditor {...props} field={props.field} />;
    default:
      return <TextEditor {...props} />;
  }
}

export function Issues({ issues, id }: { issues: Issue[]; id?: string }): ReactNode {
  if (issues.length === 0) return null;
  return (
    <ul className="mf-issues" id={id} role="alert">
      {issues.map((i, k) => (
        <li key={k}>{issueText(i)}</li>
      ))}
    </ul>
  );
}

function placeholderOf(f: Field): string {
  if (f.hasDefault) return `default: ${summarize(f.default, 40)}`;
  if (!f.required) return "not set";
  switch (f.kind) {
    case "numberList":
      return "e.g. 1, 2, 3";
    case "numberOrList":
      return "a number, or 1, 2, 3";
    case "matrix":
      return "one row per line: 1, 2, 3";
    default:
      return describeType(f);
  }
}

function TextEditor({
  field,
  value,
  onChange,
  issues,
  disabled,
  label,
  id,
  onCommit,
  onRevert,
}: EditorProps): ReactNode {
  const [text, setText] = useState(() => formatText(field, value));
  // The value this editor last reported: a different value comes from outside (revert, reset).
  const reported = useRef<unknown>(value);
  useEffect(() => {
    if (value !== reported.current) {
      reported.current = value;
      setText(formatText(field, value));
    }
  }, [field, value]);
  const issuesId = useId();
  const multi = field.kind === "matrix" || field.kind === "json";
  const change = (t: string): void => {
    setText(t);
    const r = parseText(field, t);
    const v = r.ok ? r.value : new InvalidText(t, r.error);
    reported.current = v;
    onChange(v);
  };
  const onKeyDown = (e: KeyboardEvent<HTMLInputElement | HTMLTextAreaElement>): void => {
    if (e.key === "Enter" && !multi) {
      e.preventDefault();
      onCommit?.(reported.current);
    } else if (e.key === "Escape" && onRevert) {
      e.preventDefault();
      onRevert();
    }
  };
  const common = {
    id,
    value: text,
    disabled,
    "aria-label": label,
    "aria-invalid": issues.length > 0,
    "aria-describedby": issues.length ? issuesId : undefined,
    placeholder: placeholderOf(field),
    spellCheck: false,
    autoComplete: "off",
    onKeyDown,
    onBlur: () => onCommit?.(reported.current),
  };
  const numeric =
    field.kind === "number" || field.kind === "numberList" || field.kind === "numberOrList";
  return (
    <span className="mf-text">
      {multi ? (
        <textarea
          {...common}
          className="mf-input mf-area"
          rows={Math.min(12, Math.max(2, text.split("\n").length + 1))}
          onChange={(e) => change(e.target.value)}
        />
      ) : (
        <input
          {...common}
          className={`mf-input${field.kind === "number" ? " mf-num" : ""}`}
          type="text"
          inputMode={
            field.kind === "number" && field.integer ? "numeric" : numeric ? "decimal" : "text"
          }
          onChange={(e) => change(e.target.value)}
        />
      )}
      <Issues issues={issues} id={issuesId} />
    </span>
  );
}

function BooleanEditor({
  value,
  onChange,
  disabled,
  label,
  id,
  onCommit,
  field,
  issues,
}: EditorProps): ReactNode {
  const checked = value === undefined ? field.default === true : value === true;
  return (
    <span className="mf-bool">
      <input
        id={id}
        type="checkbox"
        aria-label={label}
        checked={checked}
        disabled={disabled}
        onChange={(e) => {
          onChange(e.target.checked);
          onCommit?.(e.target.checked);
        }}
      />
      <span className="mf-bool-text">{checked ? "yes" : "no"}</span>
      <Issues issues={issues} />
    </span>
  );
}

function EnumEditor({
  field,
  value,
  onChange,
  disabled,
  label,
  id,
  onCommit,
  issues,
}: EditorProps & { field: EnumField }): ReactNode {
  const index = field.options.findIndex((o) => Object.is(o.value, value) || o.value === value);
  // "Not set" is a choice only for optional params without a default.
  const unset = !field.required && !field.hasDefault;
  return (
    <span className="mf-enum">
      <select
        id={id}
        className="mf-input"
        aria-label={label}
        aria-invalid={issues.length > 0}
        disabled={disabled}
        value={index >= 0 ? String(index) : ""}
        onChange={(e) => {
          const v =
            e.target.value === "" ? undefined : field.options[Number(e.target.value)]!.value;
          onChange(v);
          onCommit?.(v);
        }}
      >
        {(unset || index < 0) && (
          <option value="">
            {field.hasDefault ? `default (${summarize(field.default, 30)})` : "— not set —"}
          </option>
        )}
        {field.options.map((o, k) => (
          <option key={k} value={String(k)}>
            {o.label}
          </option>
        ))}
      </select>
      <Issues issues={issues} />
    </span>
  );
}

const isRecord = (v: unknown): v is Record<string, unknown> =>
  v !== null && typeof v === "object" && !Array.isArray(v) && !(v instanceof InvalidText);

function SubfieldLabel({ f, htmlFor }: { f: Field; htmlFor: string }): ReactNode {
  return (
    <label className="mf-sublabel" htmlFor={htmlFor} title={f.description}>
      {f.name}
      {f.required && (
        <span className="mf-req" aria-label="required">
          *
        </span>
      )}
    </label>
  );
}

function ObjectEditor({
  field,
  value,
  onChange,
  issues,
  disabled,
  label,
}: EditorProps & { field: ObjectField }): ReactNode {
  const obj = isRecord(value) ? value : {};
  const base = useId();
  const own = issues.filter((i) => i.path.length === 0);
  // Keys the schema does not list (only reported, the validator says they are unknown).
  const extra = issues.filter(
    (i) => i.path.length === 1 && !field.fields.some((f) => f.name === i.path[0]),
  );
  return (
    <fieldset className="mf-object" disabled={disabled} aria-label={label}>
      {field.fields.map((f) => {
        const id = `${base}-${f.name}`;
        return (
          <div className="mf-subrow" key={f.name}>
            <SubfieldLabel f={f} htmlFor={id} />
            <FieldEditor
              field={f}
              id={id}
              label={`${label}.${f.name}`}
              value={obj[f.name]}
              disabled={disabled}
              issues={issuesUnder(issues, [f.name])}
              onChange={(v) => {
                const next = { ...obj };
                if (v === undefined) delete next[f.name];
                else next[f.name] = v;
                onChange(next);
              }}
            />
          </div>
        );
      })}
      <Issues issues={[...own, ...extra]} />
    </fieldset>
  );
}

function ListEditor({
  field,
  value,
  onChange,
  issues,
  disabled,
  label,
}: EditorProps & { field: ListField }): ReactNode {
  const items = Array.isArray(value) ? value : [];
  const own = issues.filter((i) => i.path.length === 0);
  const canAdd = field.maxItems === undefined || items.length < field.maxItems;
  const set = (i: number, v: unknown): void => {
    const next = items.slice();
    next[i] = v;
    onChange(next);
  };
  const move = (i: number, d: number): void => {
    const next = items.slice();
    const [x] = next.splice(i, 1);
    next.splice(i + d, 0, x);
    onChange(next);
  };
  return (
    <fieldset className="mf-list" disabled={disabled} aria-label={label}>
      <ol className="mf-items">
        {items.map((item, i) => (
          <li key={i} className="mf-item">
            <span className="mf-index">{i}</span>
            <FieldEditor
              field={field.item}
              label={`${label}[${i}]`}
              value={item}
              disabled={disabled}
              issues={issuesUnder(issues, [i])}
              onChange={(v) => set(i, v)}
            />
            {!disabled && (
              <span className="mf-item-tools">
                <button
                  type="button"
                  className="mf-mini"
                  aria-label={`move ${label}[${i}] up`}
                  disabled={i === 0}
                  onClick={() => move(i, -1)}
                >
                  ↑
                </button>
                <button
                  type="button"
                  className="mf-mini"
                  aria-label={`move ${label}[${i}] down`}
                  disabled={i === items.length - 1}
                  onClick={() => move(i, 1)}
                >
                  ↓
                </button>
                <button
                  type="button"
                  className="mf-mini"
                  aria-label={`remove ${label}[${i}]`}
                  onClick={() => onChange(items.filter((_x, k) => k !== i))}
                >
                  ✕
                </button>
              </span>
            )}
          </li>
        ))}
      </ol>
      {!disabled && (
        <button
          type="button"
          className="mf-add"
          disabled={!canAdd}
          onClick={() => onChange([...items, emptyValue(field.item)])}
        >
          + add item
        </button>
      )}
      <Issues issues={own} />
    </fieldset>
  );
}

function RecordEditor({
  field,
  value,
  onChange,
  issues,
  disabled,
  label,
}: EditorProps & { field: RecordField }): ReactNode {
  const obj = isRecord(value) ? value : {};
  const entries = Object.entries(obj);
  const own = issues.filter((i) => i.path.length === 0);
  const [keyError, setKeyError] = useState<{ index: number; message: string } | null>(null);
  const rename = (i: number, to: string): void => {
    const from = entries[i]![0];
    if (to === from) {
      setKeyError(null);
      return;
    }
    if (to === "" || to in obj) {
      setKeyError({ index: i, message: to === "" ? "a name is needed" : `'${to}' exists already` });
      return;
    }
    setKeyError(null);
    onChange(Object.fromEntries(entries.map(([k, v], j) => (j === i ? [to, v] : [k, v]))));
  };
  const add = (): void => {
    let n = entries.length + 1;
    while (`name${n}` in obj) n++;
    onChange({ ...obj, [`name${n}`]: emptyValue(field.value) });
  };
  return (
    <fieldset className="mf-record" disabled={disabled} aria-label={label}>
      {entries.map(([k, v], i) => (
        <div className="mf-subrow" key={k}>
          <span className="mf-key">
            <input
              className="mf-input mf-keyinput"
              aria-label={`${label}: name of entry ${i + 1}`}
              defaultValue={k}
              disabled={disabled}
              spellCheck={false}
              onBlur={(e) => rename(i, e.target.value.trim())}
              onKeyDown={(e) => {
                if (e.key === "Enter") rename(i, e.currentTarget.value.trim());
              }}
            />
            {keyError?.index === i && <Issues issues={[{ path: [], message: keyError.message }]} />}
          </span>
          <FieldEditor
            field={field.value}
            label={`${label}.${k}`}
            value={v}
            disabled={disabled}
            issues={issuesUnder(issues, [k])}
            onChange={(nv) => onChange({ ...obj, [k]: nv })}
          />
          {!disabled && (
            <button
              type="button"
              className="mf-mini"
              aria-label={`remove ${label}.${k}`}
              onClick={() => onChange(Object.fromEntries(entries.filter((_e, j) => j !== i)))}
            >
              ✕
            </button>
          )}
        </div>
      ))}
      {!disabled && (
        <button type="button" className="mf-add" onClick={add}>
          + add entry
        </button>
      )}
      <Issues issues={own} />
    </fieldset>
  );
}
