/**
 * The editor's file: Apply (the engine loads the text and starts it), Save… (a download) and
 * starting over from an example or an empty pipeline (undoable).
 */
import { useState } from "react";
import type { GraphInfo } from "../../engine/protocol";
import type { EngineClient, Reply } from "../client/engine-client";
import { download } from "../graph/block-table";
import { savedLiveValues } from "./live-values-bar";
import type { EditorModel } from "./use-editor";
import type { EditorApplied } from "./use-editor-applied";
import type { Notify } from "./use-editor-edits";
import type { EditorSelection } from "./use-editor-selection";

export const EMPTY_FILE = "pipelines/untitled.yaml";

export interface EditorFileOptions {
  ed: EditorModel;
  client: EngineClient;
  graph: GraphInfo | undefined;
  applied: EditorApplied;
  selection: EditorSelection;
  onApply(file: string, text: string): Promise<Reply>;
  onNotify: Notify;
}

export interface EditorFile {
  /** Changes when another pipeline is started from: the canvas fits it in view. */
  fitKey: number;
  apply(): Promise<void>;
  save(): void;
  /** `file`: an example's path, "(empty)" for an empty pipeline, "" for none. */
  pickTemplate(file: string): Promise<void>;
}

interface FileContext extends EditorFileOptions {
  /** The editor goes on with this text: nothing selected, all of it in view. */
  startOver(text: string, file: string): void;
}

async function apply(c: FileContext): Promise<void> {
  const { ed, onNotify } = c;
  const text = ed.text;
  const r = await c.onApply(ed.file, text);
  c.applied.setApplied(text, r.diagnostics ?? []);
  if (r.ok) onNotify(`Applied: ${ed.file.split("/").pop()} restarted with the edits`);
  else
    onNotify(
      `Not applied: ${r.diagnostics?.find((d) => d.severity === "error")?.message ?? r.message ?? "the engine refused the pipeline"}`,
      "error",
    );
}

function save(c: FileContext): void {
  const { ed } = c;
  const name = ed.file.split("/").pop() || "pipeline.yaml";
  download(name, ed.text);
  c.onNotify(`Saved ${name} (downloaded)`);
  // The text that runs: the live values it has are the file's now (their markers clear).
  if (!c.applied.dirty && c.graph !== undefined) void savedLiveValues(c.client, ed.text, ed.blocks);
}

async function pickTemplate(c: FileContext, file: string): Promise<void> {
  if (file === "") return;
  if (file === "(empty)") {
    c.startOver("", EMPTY_FILE);
    return;
  }
  try {
    const r = await fetch(file);
    if (!r.ok) throw new Error(`HTTP ${r.status}`);
    c.startOver(await r.text(), file);
  } catch (e) {
    c.onNotify(`Cannot read ${file}: ${(e as Error).message}`, "error");
  }
}

export function useEditorFile(options: EditorFileOptions): EditorFile {
  const [fitKey, setFitKey] = useState(0);
  const c: FileContext = {
    ...options,
    startOver: (text, file) => {
      options.ed.reset(text, file);
      options.selection.setSelected(null);
      setFitKey((k) => k + 1);
    },
  };
  return {
    fitKey,
    apply: () => apply(c),
    save: () => save(c),
    pickTemplate: (file) => pickTemplate(c, file),
  };
}
