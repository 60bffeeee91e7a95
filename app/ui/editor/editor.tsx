/**
 * Edit mode (issue 8): palette, canvas, inspector and the YAML side by side, all on one text
 * (the pipeline file) through the document model. Structural edits reach the engine with
 * "Apply" (the pipeline is loaded again and started: a short, visible restart); live params of a
 * running block apply at once. "Save…" downloads the file. The engine checks every text as
 * `mosaic validate` does (use-validation.ts); a text with errors, or not checked yet, is neither
 * applied nor saved.
 *
 * The parts: use-editor-catalog.ts (the block catalog), use-editor-document.ts (the text, its
 * history and check), use-editor-selection.ts, use-editor-applied.ts (the text that runs, the
 * problems shown), use-editor-edits.ts (block edits), use-editor-file.ts (Apply, Save…, new
 * from an example), use-editor-keys.ts (shortcuts), editor-toolbar.tsx, editor-inspector.tsx.
 */
import type { ReactNode } from "react";
import type { BlockTypeInfo, CatalogInfo, GraphInfo } from "../../engine/protocol";
import type { EngineClient, Reply } from "../client/engine-client";
import { EditCanvas } from "./edit-canvas";
import { EditorInspector } from "./editor-inspector";
import { EditorToolbar, type TemplateEntry } from "./editor-toolbar";
import type { EditIssue } from "./model";
import { Palette } from "./palette";
import { SidePane } from "./side-pane";
import { TextView } from "./text-view";
import type { EditorModel } from "./use-editor";
import { useEditorApplied } from "./use-editor-applied";
import { useEditorCatalog } from "./use-editor-catalog";
import { useEditorDocument } from "./use-editor-document";
import { useEditorEdits, type EditorEdits } from "./use-editor-edits";
import { useEditorFile } from "./use-editor-file";
import { useEditorKeys } from "./use-editor-keys";
import { useEditorSelection, type EditorSelection } from "./use-editor-selection";

export type { TemplateEntry } from "./editor-toolbar";
export { EMPTY_FILE } from "./use-editor-file";

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

interface EditorBodyProps {
  ed: EditorModel;
  catalog: CatalogInfo | undefined;
  types: Map<string, BlockTypeInfo>;
  issues: EditIssue[];
  graph: GraphInfo | undefined;
  running: boolean;
  selection: EditorSelection;
  edits: EditorEdits;
  fitKey: number;
}

/** Palette, canvas, and the inspector above (or beside, in tabs) the YAML. */
function EditorBody(props: EditorBodyProps): ReactNode {
  const { ed, catalog, types, issues, graph, running, selection, edits, fitKey } = props;
  const { sel, selectedEdge } = selection;
  return (
    <div className="editor__body">
      <Palette catalog={catalog} onAdd={(t) => edits.addBlock(t)} />
      <EditCanvas
        blocks={ed.blocks}
        issues={issues}
        catalog={catalog}
        graph={graph}
        running={running}
        selected={sel?.name ?? null}
        selectedEdge={selectedEdge}
        onSelect={selection.selectBlock}
        onSelectEdge={selection.selectEdge}
        onAdd={(type, at) => edits.addBlock(type, at)}
        onConnect={(from, to) => void edits.run((d) => d.connect(from, to))}
        onMove={(b, to) => void edits.run((d) => d.setLayout(b, to))}
        onDelete={edits.removeSelected}
        fitKey={fitKey}
      />
      <SidePane
        selected={sel?.name ?? null}
        inspector={
          <EditorInspector
            sel={sel}
            ed={ed}
            edits={edits}
            types={types}
            issues={issues}
            graph={graph}
          />
        }
        text={<TextView text={ed.text} issues={issues} catalog={catalog} onChange={ed.setText} />}
      />
    </div>
  );
}

export function Editor(props: EditorProps): ReactNode {
  const { client, graph, running, onNotify } = props;
  const { catalog, types } = useEditorCatalog(client, graph, onNotify);
  const { ed, check } = useEditorDocument(
    client,
    props.initialText,
    props.initialFile,
    props.onDraft,
  );
  const selection = useEditorSelection(ed.blocks);
  const applied = useEditorApplied(ed, check, graph ? props.appliedText : undefined);
  const { issues, dirty } = applied;
  const edits = useEditorEdits({ ed, selection, types, client, graph, running, applied, onNotify });
  const file = useEditorFile({
    ed,
    client,
    graph,
    applied,
    selection,
    onApply: props.onApply,
    onNotify,
  });
  const { sel, selectedEdge } = selection;
  useEditorKeys({ undo: ed.undo, redo: ed.redo, duplicate: sel ? edits.duplicate : () => {} });

  return (
    <div
      className="editor"
      data-dirty={String(dirty)}
      data-errors={applied.errors}
      data-checking={String(check.checking)}
      data-broken={String(ed.broken)}
    >
      <EditorToolbar
        ed={ed}
        templates={props.templates}
        status={{
          applying: props.applying,
          errors: applied.errors,
          checking: check.checking,
          dirty,
          loaded: graph !== undefined,
        }}
        blockSelected={sel !== undefined}
        anySelected={sel !== undefined || selectedEdge !== null}
        onPickTemplate={file.pickTemplate}
        onDuplicate={edits.duplicate}
        onDelete={edits.removeSelected}
        onNotify={onNotify}
        // The running pipeline has the values: a text that ran before still does.
        onTaken={() => {
          if (!dirty) applied.follow();
        }}
        onApply={file.apply}
        onSave={file.save}
        onClose={props.onClose}
      />
      <EditorBody
        ed={ed}
        catalog={catalog}
        types={types}
        issues={issues}
        graph={graph}
        running={running}
        selection={selection}
        edits={edits}
        fitKey={file.fitKey}
      />
    </div>
  );
}
