/**
 * The editor's structural edits, each one operation of the document model on the text: add,
 * delete (a block or a connection), duplicate and rename a block, and set a param (at once in
 * the engine too when it is live in the pipeline that runs this very text).
 */
import { useCallback } from "react";
import type { BlockTypeInfo, GraphInfo } from "../../engine/protocol";
import type { EngineClient } from "../client/engine-client";
import type { SetResult } from "../forms/params-form";
import type { EditableDocument } from "./doc";
import type { EditBlock } from "./model";
import type { EditorModel } from "./use-editor";
import type { EditorApplied } from "./use-editor-applied";
import type { EditorSelection } from "./use-editor-selection";

export type Notify = (message: string, level?: "info" | "error") => void;

type Op = (doc: EditableDocument) => void;

interface Point {
  x: number;
  y: number;
}

export interface EditorEditsOptions {
  ed: EditorModel;
  selection: EditorSelection;
  types: Map<string, BlockTypeInfo>;
  client: EngineClient;
  graph: GraphInfo | undefined;
  running: boolean;
  applied: EditorApplied;
  onNotify: Notify;
}

export interface EditorEdits {
  /** Applies an edit; a refusal is told, and returned. */
  run(op: Op): string | undefined;
  /** Adds a block of the type at `at` (else right of the others) and selects it. */
  addBlock(type: string, at?: Point): void;
  /** Deletes the selected connection, else the selected block. */
  removeSelected(): void;
  /** Copies the selected block under a fresh name and selects the copy. */
  duplicate(): void;
  /** Renames the selected block; returns the refusal. */
  rename(to: string): string | undefined;
  /** The inspector sets a param of the selected block. */
  setParam(param: string, value: unknown): Promise<SetResult>;
}

interface EditContext extends EditorEditsOptions {
  run(op: Op): string | undefined;
}

/** Right of the rightmost block, at the top. */
function nextSpot(blocks: readonly EditBlock[]): Point {
  const xs = blocks.map((b) => b.layout?.x ?? 0);
  return { x: xs.length ? Math.max(...xs) + 240 : 0, y: 0 };
}

function addBlock(c: EditContext, type: string, at?: Point): void {
  const t = c.types.get(type);
  const name = c.ed.freshName(t?.type ?? type);
  const layout = at ?? nextSpot(c.ed.blocks);
  if (c.run((d) => d.addBlock(name, t?.type ?? type, { layout })) === undefined) {
    c.selection.setSelected(name);
    c.selection.setSelectedEdge(null);
  }
}

/** Takes input `index` out of block `to` (a connection's id is `to#index`). */
function removeConnection(c: EditContext, edge: string): void {
  const [to, index] = edge.split("#") as [string, string];
  const b = c.ed.blocks.find((x) => x.name === to);
  if (!b) return;
  const rest = b.inputs
    .filter((_i, k) => k !== Number(index))
    .map((i) => `${i.subscribed ? "" : "-"}${i.source}`);
  c.run((d) => d.setInputs(to, rest));
}

function removeSelected(c: EditContext): void {
  const { sel, selectedEdge } = c.selection;
  if (selectedEdge !== null) {
    removeConnection(c, selectedEdge);
    c.selection.setSelectedEdge(null);
  } else if (sel) {
    c.run((d) => d.removeBlock(sel.name));
    c.selection.setSelected(null);
  }
}

function duplicate(c: EditContext): void {
  const { sel } = c.selection;
  if (!sel) return;
  const name = c.ed.freshName(sel.name);
  if (c.run((d) => d.duplicateBlock(sel.name, name)) === undefined) c.selection.setSelected(name);
}

function rename(c: EditContext, to: string): string | undefined {
  const { sel } = c.selection;
  if (!sel || to === sel.name) return undefined;
  const e = c.ed.edit((d) => d.renameBlock(sel.name, to));
  if (e === undefined) c.selection.setSelected(to);
  return e;
}

/** A live param of the running pipeline: set in the engine, then in the text. */
async function setLiveParam(
  c: EditContext,
  block: string,
  param: string,
  value: unknown,
): Promise<SetResult> {
  const r = await c.client.setParam(block, param, value);
  if (!r.ok) return { ok: false, message: r.message ?? "refused" };
  const e = c.ed.edit((d) => d.setParam(block, param, value));
  // The running pipeline has the value too: the applied text follows.
  if (e === undefined) c.applied.follow();
  return e === undefined ? { ok: true, message: "applied (live)" } : { ok: false, message: e };
}

async function setParam(c: EditContext, param: string, value: unknown): Promise<SetResult> {
  const { sel } = c.selection;
  if (!sel) return { ok: false, message: "no block" };
  const live = c.graph?.blocks.find(
    (b) => b.name === sel.name && b.type === c.types.get(sel.type)?.type,
  );
  if (c.running && live && live.live.includes(param) && !c.applied.dirty)
    return setLiveParam(c, sel.name, param, value);
  const e = c.ed.edit((d) => d.setParam(sel.name, param, value));
  return e === undefined
    ? { ok: true, message: c.running ? "changed in the file: Apply to run it" : "changed" }
    : { ok: false, message: e };
}

export function useEditorEdits(options: EditorEditsOptions): EditorEdits {
  const { ed, onNotify } = options;
  const run = useCallback(
    (op: Op): string | undefined => {
      const e = ed.edit(op);
      if (e !== undefined) onNotify(e, "error");
      return e;
    },
    [ed, onNotify],
  );
  const c: EditContext = { ...options, run };
  return {
    run,
    addBlock: (type, at) => addBlock(c, type, at),
    removeSelected: () => removeSelected(c),
    duplicate: () => duplicate(c),
    rename: (to) => rename(c, to),
    setParam: (param, value) => setParam(c, param, value),
  };
}
