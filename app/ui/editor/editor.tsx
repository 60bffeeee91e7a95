/**
 * Edit mode (issue 8): palette, canvas, inspector and the YAML side by side, all on one text
 * (the pipeline file) through the document model. Structural edits reach the engine with
 * "Apply" (the pipeline is loaded again and started: a short, visible restart); live params of a
 * running block apply at once. "Save…" downloads the file. The engine checks every text as
 * `mosaic validate` does (use-validation.ts); a text with errors, or not checked yet, is neither
 * applied nor saved.
 */
import { useCallback, useEffect, useMemo, useRef, useState, type ReactNode } from "react";
import type { Diagnostic } from "../../engine/diagnostics";
import type { CatalogInfo, GraphInfo } from "../../engine/protocol";
import type { EngineClient, Reply } from "../client/engine-client";
import { download } from "../graph/block-table";
import type { SetResult } from "../forms/params-form";
import { EditCanvas } from "./edit-canvas";
import { Inspector } from "./inspector";
import { savedLiveValues, TakeLiveValues } from "./live-values-bar";
import { typeIndex, type EditIssue } from "./model";
import { Palette } from "./palette";
import { TextView } from "./text-view";
import { SidePane } from "./side-pane";
import { useEditor } from "./use-editor";
import { issueFromDiagnostic, useValidation } from "./use-validation";

export interface TemplateEntry {
  file: string;
  title: string;
}

export interface EditorProps {
  client: EngineClient;
  initialText: string;
  initialFile: string;
  /** The text the engine runs now (undefined: none), to tell whether there is something to apply. */
  appliedText: string | undefined;
  /** The examples (pipelines/index.json) offered as templates. */
  templates: readonly TemplateEntry[];
  graph: GraphInfo | undefined;
  running: boolean;
  /** An Apply is under way (the pipeline restarts). */
  applying: boolean;
  onApply(file: string, text: string): Promise<Reply>;
  onNotify(message: string, level?: "info" | "error"): void;
  /** Called with the text whenever it changes (the shell keeps it for the next edit mode). */
  onDraft?(file: string, text: string): void;
  onClose(): void;
}

export const EMPTY_FILE = "pipelines/untitled.yaml";

/** The checked problems, then those of the last Apply of the same text that they lack. */
function withApplied(issues: EditIssue[], applied: readonly Diagnostic[]): EditIssue[] {
  const key = (i: EditIssue): string => `${i.line}:${i.col}:${i.message}`;
  const seen = new Set(issues.map(key));
  const extra = applied
    .filter((d) => d.severity !== "info")
    .map(issueFromDiagnostic)
    .filter((i) => !seen.has(key(i)));
  return extra.length > 0 ? [...issues, ...extra] : issues;
}

export function Editor(props: EditorProps): ReactNode {
  const { client, graph, running, applying, onNotify } = props;
  const [catalog, setCatalog] = useState<CatalogInfo | undefined>();
  // The catalog holds the loaded pipeline's own blocks too (`Pipeline: { Blocks }`): asked again
  // when another pipeline, or a new version of its blocks, is loaded.
  const loadedTypes = graph ? `${graph.file}:${graph.blocks.map((b) => b.type).join(",")}` : "";
  useEffect(() => {
    let live = true;
    void client.catalog().then((c) => {
      if (live) setCatalog(c);
      if (!c) onNotify("The engine did not send its block catalog", "error");
    });
    return () => {
      live = false;
    };
  }, [client, onNotify, loadedTypes]);

  const ed = useEditor(props.initialText, props.initialFile);
  const check = useValidation(client, ed.file, ed.text);
  const [selected, setSelected] = useState<string | null>(null);
  const [selectedEdge, setSelectedEdge] = useState<string | null>(null);
  const [applied, setApplied] = useState<{ text: string; diagnostics: Diagnostic[] }>({
    text: graph && props.appliedText !== undefined ? props.appliedText : "\u0000",
    diagnostics: [],
  });
  const types = useMemo(() => typeIndex(catalog), [catalog]);
  const [fitKey, setFitKey] = useState(0);

  const { onDraft } = props;
  useEffect(() => onDraft?.(ed.file, ed.text), [onDraft, ed.file, ed.text]);

  // What `mosaic validate` says of the text (the engine checks it), and what the last Apply of
  // the same text added (a load instantiates with the real devices' bridges).
  const issues = useMemo(
    () =>
      applied.text === ed.text ? withApplied(check.issues, applied.diagnostics) : check.issues,
    [check.issues, ed.text, applied],
  );
  const errors = issues.filter((i) => i.severity === "error").length;
  const dirty = applied.text !== ed.text;

  const run = useCallback(
    (op: Parameters<typeof ed.edit>[0]): string | undefined => {
      const e = ed.edit(op);
      if (e !== undefined) onNotify(e, "error");
      return e;
    },
    [ed, onNotify],
  );

  // Blocks that vanished (undo, text edit) are no longer selected.
  const sel = selected !== null ? ed.blocks.find((b) => b.name === selected) : undefined;

  const addBlock = (type: string, at?: { x: number; y: number }): void => {
    const t = types.get(type);
    const name = ed.freshName(t?.type ?? type);
    const layout =
      at ??
      (() => {
        const xs = ed.blocks.map((b) => b.layout?.x ?? 0);
        return { x: xs.length ? Math.max(...xs) + 240 : 0, y: 0 };
      })();
    if (run((d) => d.addBlock(name, t?.type ?? type, { layout })) === undefined) {
      setSelected(name);
      setSelectedEdge(null);
    }
  };

  const removeSelected = (): void => {
    if (selectedEdge !== null) {
      const [to, index] = selectedEdge.split("#") as [string, string];
      const b = ed.blocks.find((x) => x.name === to);
      if (b) {
        const rest = b.inputs
          .filter((_i, k) => k !== Number(index))
          .map((i) => `${i.subscribed ? "" : "-"}${i.source}`);
        run((d) => d.setInputs(to, rest));
      }
      setSelectedEdge(null);
    } else if (sel) {
      run((d) => d.removeBlock(sel.name));
      setSelected(null);
    }
  };

  const duplicate = (): void => {
    if (!sel) return;
    const name = ed.freshName(sel.name);
    if (run((d) => d.duplicateBlock(sel.name, name)) === undefined) setSelected(name);
  };

  const apply = async (): Promise<void> => {
    const text = ed.text;
    const r = await props.onApply(ed.file, text);
    setApplied({ text, diagnostics: r.diagnostics ?? [] });
    if (r.ok) onNotify(`Applied: ${ed.file.split("/").pop()} restarted with the edits`);
    else
      onNotify(
        `Not applied: ${r.diagnostics?.find((d) => d.severity === "error")?.message ?? r.message ?? "the engine refused the pipeline"}`,
        "error",
      );
  };

  const save = (): void => {
    const name = ed.file.split("/").pop() || "pipeline.yaml";
    download(name, ed.text);
    onNotify(`Saved ${name} (downloaded)`);
    // The text that runs: the live values it has are the file's now (their markers clear).
    if (!dirty && graph !== undefined) void savedLiveValues(client, ed.text, ed.blocks);
  };

  const pickTemplate = async (file: string): Promise<void> => {
    if (file === "") return;
    if (file === "(empty)") {
      ed.reset("", EMPTY_FILE);
      setSelected(null);
      setFitKey((k) => k + 1);
      return;
    }
    try {
      const r = await fetch(file);
      if (!r.ok) throw new Error(`HTTP ${r.status}`);
      ed.reset(await r.text(), file);
      setSelected(null);
      setFitKey((k) => k + 1);
    } catch (e) {
      onNotify(`Cannot read ${file}: ${(e as Error).message}`, "error");
    }
  };

  const onParam = async (param: string, value: unknown): Promise<SetResult> => {
    if (!sel) return { ok: false, message: "no block" };
    const live = graph?.blocks.find(
      (b) => b.name === sel.name && b.type === types.get(sel.type)?.type,
    );
    if (running && live && live.live.includes(param) && !dirty) {
      const r = await client.setParam(sel.name, param, value);
      if (!r.ok) return { ok: false, message: r.message ?? "refused" };
      const e = ed.edit((d) => d.setParam(sel.name, param, value));
      // The running pipeline has the value too: the applied text follows.
      if (e === undefined) setApplied((a) => ({ ...a, text: ed.textNow() }));
      return e === undefined ? { ok: true, message: "applied (live)" } : { ok: false, message: e };
    }
    const e = ed.edit((d) => d.setParam(sel.name, param, value));
    return e === undefined
      ? { ok: true, message: running ? "changed in the file: Apply to run it" : "changed" }
      : { ok: false, message: e };
  };

  // Ctrl+Z / Ctrl+Shift+Z (Ctrl+Y) / Ctrl+D anywhere on the page while editing, except in the
  // inspector's fields (their own text undo).
  const keys = useRef({ undo: ed.undo, redo: ed.redo, duplicate: (): void => {} });
  keys.current = { undo: ed.undo, redo: ed.redo, duplicate: sel ? duplicate : () => {} };
  useEffect(() => {
    const onKey = (e: KeyboardEvent): void => {
      if (!(e.ctrlKey || e.metaKey) || e.altKey) return;
      const target = e.target as HTMLElement | null;
      if (target && (target.tagName === "INPUT" || target.tagName === "SELECT")) return;
      const k = e.key.toLowerCase();
      if (k === "z" && !e.shiftKey) keys.current.undo();
      else if ((k === "z" && e.shiftKey) || k === "y") keys.current.redo();
      else if (k === "d") keys.current.duplicate();
      else return;
      e.preventDefault();
    };
    window.addEventListener("keydown", onKey);
    return () => window.removeEventListener("keydown", onKey);
  }, []);

  return (
    <div
      className="editor"
      data-dirty={String(dirty)}
      data-errors={errors}
      data-checking={String(check.checking)}
      data-broken={String(ed.broken)}
    >
      <div className="editor__bar" role="toolbar" aria-label="Editor">
        <label className="editor__template">
          <span>New from</span>
          <select
            value=""
            onChange={(e) => void pickTemplate(e.target.value)}
            aria-label="New pipeline from an example"
          >
            <option value="">example…</option>
            <option value="(empty)">Empty pipeline</option>
            {props.templates.map((t) => (
              <option key={t.file} value={t.file}>
                {t.file.replace(/^pipelines\//, "")}
              </option>
            ))}
          </select>
        </label>
        <button type="button" onClick={ed.undo} disabled={!ed.canUndo} title="Undo (Ctrl+Z)">
          Undo
        </button>
        <button type="button" onClick={ed.redo} disabled={!ed.canRedo} title="Redo (Ctrl+Shift+Z)">
          Redo
        </button>
        <button
          type="button"
          onClick={duplicate}
          disabled={!sel}
          title="Duplicate the block (Ctrl+D)"
        >
          Duplicate
        </button>
        <button
          type="button"
          onClick={removeSelected}
          disabled={!sel && selectedEdge === null}
          title="Delete the selected block or connection (Delete)"
        >
          Delete
        </button>
        <TakeLiveValues
          ed={ed}
          onNotify={onNotify}
          // The running pipeline has the values: a text that ran before still does.
          onTaken={() => {
            if (!dirty) setApplied((a) => ({ ...a, text: ed.textNow() }));
          }}
        />
        <span className="toolbar__spacer" />
        <span className="editor__state" role="status" aria-live="polite">
          {applying
            ? "restarting…"
            : errors > 0
              ? `${errors} problem${errors === 1 ? "" : "s"}: fix to apply or save`
              : dirty
                ? "changes not applied"
                : "applied"}
        </span>
        <button
          type="button"
          className="primary"
          onClick={() => void apply()}
          disabled={
            applying ||
            errors > 0 ||
            check.checking ||
            ed.blocks.length === 0 ||
            (!dirty && graph !== undefined)
          }
          title="Load the edited pipeline and start it (a short restart)"
        >
          Apply
        </button>
        <button
          type="button"
          onClick={save}
          disabled={errors > 0 || check.checking}
          title={
            errors > 0
              ? "Fix the problems first"
              : check.checking
                ? "The text is being checked"
                : "Download the pipeline file"
          }
        >
          Save…
        </button>
        <button type="button" onClick={props.onClose} title="Leave edit mode">
          Done
        </button>
      </div>
      <div className="editor__body">
        <Palette catalog={catalog} onAdd={(t) => addBlock(t)} />
        <EditCanvas
          blocks={ed.blocks}
          issues={issues}
          catalog={catalog}
          graph={graph}
          running={running}
          selected={sel?.name ?? null}
          selectedEdge={selectedEdge}
          onSelect={(b) => {
            setSelected(b);
            if (b !== null) setSelectedEdge(null);
          }}
          onSelectEdge={(e) => {
            setSelectedEdge(e);
            if (e !== null) setSelected(null);
          }}
          onAdd={(type, at) => addBlock(type, at)}
          onConnect={(from, to) => void run((d) => d.connect(from, to))}
          onMove={(b, to) => void run((d) => d.setLayout(b, to))}
          onDelete={removeSelected}
          fitKey={fitKey}
        />
        <SidePane
          selected={sel?.name ?? null}
          inspector={
            sel ? (
              <Inspector
                block={sel}
                type={types.get(sel.type)}
                issues={issues}
                runningBlock={graph?.blocks.find((b) => b.name === sel.name)}
                onRename={(to) => {
                  if (to === sel.name) return undefined;
                  const e = ed.edit((d) => d.renameBlock(sel.name, to));
                  if (e === undefined) setSelected(to);
                  return e;
                }}
                onDesiredRate={(r) => ed.edit((d) => d.setDesiredRate(sel.name, r))}
                onPath={(p) => ed.edit((d) => d.setPath(sel.name, p))}
                onInputs={(ins) => ed.edit((d) => d.setInputs(sel.name, ins))}
                onParam={onParam}
              />
            ) : (
              <p className="inspector__none">Select a block to edit it.</p>
            )
          }
          text={<TextView text={ed.text} issues={issues} catalog={catalog} onChange={ed.setText} />}
        />
      </div>
    </div>
  );
}
