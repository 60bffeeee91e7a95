/**
 * The editor's document: its text with undo/redo (use-editor.ts), the engine's check of it
 * (use-validation.ts), and the shell told of every new text (it keeps it for the next edit mode).
 */
import { useEffect } from "react";
import type { EngineClient } from "../client/engine-client";
import { useEditor, type EditorModel } from "./use-editor";
import { useValidation, type Validation } from "./use-validation";

export interface EditorDocument {
  ed: EditorModel;
  check: Validation;
}

export function useEditorDocument(
  client: EngineClient,
  initialText: string,
  initialFile: string,
  onDraft: ((file: string, text: string) => void) | undefined,
): EditorDocument {
  const ed = useEditor(initialText, initialFile);
  const check = useValidation(client, ed.file, ed.text);
  useEffect(() => onDraft?.(ed.file, ed.text), [onDraft, ed.file, ed.text]);
  return { ed, check };
}
