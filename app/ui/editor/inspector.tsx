/**
 * The inspector of the selected block in edit mode: name (rename: references follow), type with
 * its help, DesiredRate, Path, Inputs and the params form generated from the type's schema. Every
 * change goes to the document; a live param of a block that runs is also applied at once.
 */
import { useEffect, useId, useState, type ReactNode } from "react";
import type { BlockInfo, BlockTypeInfo } from "../../engine/protocol";
import { useLiveBlock } from "../client/hooks";
import { ParamsForm, type SetResult } from "../forms/params-form";
import { changedParams, missingFromText } from "./live-values";
import type { EditBlock, EditIssue } from "./model";

export interface InspectorProps {
  block: EditBlock;
  type: BlockTypeInfo | undefined;
  issues: readonly EditIssue[];
  /** The block's info in the running pipeline (same name and type), when it runs. */
  runningBlock: BlockInfo | undefined;
  onRename(to: string): string | undefined;
  onDesiredRate(rate: number | undefined): string | undefined;
  onPath(path: string | undefined): string | undefined;
  onInputs(inputs: string[]): string | undefined;
  onParam(param: string, value: unknown): Promise<SetResult>;
}

/** A text field committed with Enter or on leaving it; Escape restores the value. */
function CommitField({
  label,
  value,
  placeholder,
  hint,
  inputMode,
  onCommit,
}: {
  label: string;
  value: string;
  placeholder?: string;
  hint?: string;
  inputMode?: "decimal" | "text";
  onCommit(text: string): string | undefined;
}): ReactNode {
  const id = useId();
  const [draft, setDraft] = useState(value);
  const [error, setError] = useState<string | undefined>();
  useEffect(() => {
    setDraft(value);
    setError(undefined);
  }, [value]);
  const commit = (): void => {
    if (draft === value) return;
    const e = onCommit(draft.trim());
    setError(e);
  };
  return (
    <div className="inspector__field">
      <label htmlFor={id}>{label}</label>
      <input
        id={id}
        type="text"
        value={draft}
        placeholder={placeholder}
        inputMode={inputMode}
        aria-invalid={error !== undefined}
        aria-describedby={`${id}-hint`}
        onChange={(e) => setDraft(e.target.value)}
        onBlur={commit}
        onKeyDown={(e) => {
          if (e.key === "Enter") {
            e.preventDefault();
            commit();
          } else if (e.key === "Escape") {
            setDraft(value);
            setError(undefined);
          }
        }}
      />
      <span id={`${id}-hint`} className={error ? "inspector__error" : "inspector__hint"}>
        {error ?? hint ?? ""}
      </span>
    </div>
  );
}

/** The block as the engine would list it, for the params form (the type's schema and live). */
function blockInfo(b: EditBlock, t: BlockTypeInfo | undefined): BlockInfo {
  return {
    name: b.name,
    type: t?.type ?? b.type,
    category: t?.category ?? "",
    summary: t?.summary ?? "",
    help: t?.help ?? "",
    worker: "main",
    timer: t?.timer ?? false,
    desiredRate: b.desiredRate ?? 0,
    inputs: b.inputs.map((i) => ({ ...i })),
    outputs: [],
    views: [],
    panel: "",
    live: t?.live ?? [],
    params: b.params,
    paramsSchema: t?.paramsSchema ?? {},
    actions: [],
  };
}

/** "1–3 input(s), comma-separated; …" from the type's fewest and most inputs. */
function inputsHint(t: BlockTypeInfo): string {
  return `${t.inputs.min}${t.inputs.max === null ? "+" : t.inputs.max === t.inputs.min ? "" : `–${t.inputs.max}`} input(s), comma-separated; Block.port for another output, -Block: not subscribed`;
}

/** The inputs as typed: separated by commas or spaces, empty ones left out. */
function parseInputs(s: string): string[] {
  return s
    .split(/[,\s]+/)
    .map((x) => x.trim())
    .filter((x) => x !== "");
}

/** The block's name and its type's. */
function InspectorTitle({ name, type }: { name: string; type: string }): ReactNode {
  return (
    <h3 className="inspector__title">
      {name} <span className="inspector__type">{type || "(no type)"}</span>
    </h3>
  );
}

/** The type's summary, with its help when opened (nothing for an unknown type). */
function TypeHelp({ type: t }: { type: BlockTypeInfo | undefined }): ReactNode {
  return t ? (
    <details className="inspector__help">
      <summary>{t.summary}</summary>
      <p>{t.help}</p>
    </details>
  ) : null;
}

/** The problems of this block (nothing when it has none). */
function BlockIssues({
  block,
  issues,
}: {
  block: string;
  issues: readonly EditIssue[];
}): ReactNode {
  const mine = issues.filter((i) => i.block === block);
  return mine.length > 0 ? (
    <ul className="inspector__issues" aria-label="Problems">
      {mine.map((i, k) => (
        <li key={k}>{i.message}</li>
      ))}
    </ul>
  ) : null;
}

/** DesiredRate: empty inherits it, else a positive number of Hz. */
function RateField({ props }: { props: InspectorProps }): ReactNode {
  const { block: b, type: t } = props;
  return (
    <CommitField
      label="DesiredRate (Hz)"
      value={b.desiredRate !== undefined ? String(b.desiredRate) : ""}
      inputMode="decimal"
      placeholder={t?.requiresRate ? "required" : "inherited from the inputs"}
      onCommit={(s) => {
        if (s === "") return props.onDesiredRate(undefined);
        const n = Number(s);
        if (!Number.isFinite(n) || n <= 0) return "a positive number of Hz";
        return props.onDesiredRate(n);
      }}
    />
  );
}

/** Inputs, comma-separated ("-Block": not subscribed), with the number the type takes. */
function InputsField({ props }: { props: InspectorProps }): ReactNode {
  const { block: b, type: t } = props;
  const inputsText = b.inputs.map((i) => `${i.subscribed ? "" : "-"}${i.source}`).join(", ");
  return (
    <CommitField
      label="Inputs"
      value={inputsText}
      placeholder={t && t.inputs.min === 0 && t.inputs.max === 0 ? "none" : "e.g. Timer, Emg"}
      hint={t ? inputsHint(t) : undefined}
      onCommit={(s) => props.onInputs(parseInputs(s))}
    />
  );
}

/** The params form generated from the type's schema (a hint for an unknown type). */
function BlockParams({ props }: { props: InspectorProps }): ReactNode {
  return props.type ? (
    <ParamsForm
      block={blockInfo(props.block, props.type)}
      engineState="loaded"
      onSet={(param, value) => props.onParam(param, value)}
      onEditStatic={(param, value) => props.onParam(param, value)}
    />
  ) : (
    <p className="inspector__hint">Unknown type: no params form.</p>
  );
}

export function Inspector(props: InspectorProps): ReactNode {
  const { block: b, type: t, issues } = props;
  return (
    <section className="inspector" aria-label={`Inspector: ${b.name}`} data-inspector={b.name}>
      <InspectorTitle name={b.name} type={t?.type ?? b.type} />
      <TypeHelp type={t} />
      <BlockIssues block={b.name} issues={issues} />
      <CommitField
        label="Name"
        value={b.name}
        hint="Enter to rename (inputs that name it follow)"
        onCommit={(s) => props.onRename(s)}
      />
      <RateField props={props} />
      <InputsField props={props} />
      <CommitField
        label="Path (log)"
        value={b.path ?? ""}
        placeholder="not logged"
        onCommit={(s) => props.onPath(s === "" ? undefined : s)}
      />
      <h4 className="inspector__params-title">Params</h4>
      <RunningValues block={b} running={props.runningBlock} />
      <BlockParams props={props} />
    </section>
  );
}

/**
 * The live values the engine runs this block with that the text lacks (changed since loaded,
 * from any tab): the form below shows the text's values (issue 17, defect 1).
 */
function RunningValues({
  block,
  running,
}: {
  block: EditBlock;
  running: BlockInfo | undefined;
}): ReactNode {
  const now = useLiveBlock(running);
  if (now === undefined) return null;
  const changes = changedParams(now).map((param) => ({
    block: block.name,
    param,
    value: now.params[param],
    file: now.fileParams?.[param],
  }));
  const missing = missingFromText(changes, [block]);
  if (missing.length === 0) return null;
  return (
    <p className="inspector__running" role="note" data-running-values={missing.length}>
      The engine runs{" "}
      {missing
        .map(
          (c) =>
            `${c.param} = ${JSON.stringify(c.value)} (the text: ${JSON.stringify(block.params[c.param] ?? null)})`,
        )
        .join(", ")}
      , changed since loaded: <em>Take live values</em> sets them in the text.
    </p>
  );
}
