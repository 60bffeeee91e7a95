/**
 * Edit mode (issue 8): the editor holds its own text; Apply loads it and starts it. A draft is
 * kept while leaving edit mode (said so), and dropped when another load happens.
 */
import { useCallback, useEffect, useRef, useState } from "react";
import { EMPTY_FILE } from "../editor/editor";
import type { Notify } from "./use-notice";
import { useLatest, type Pipeline } from "./use-shell-state";

export interface EditMode {
  editing: boolean;
  /** An Apply is under way (the pipeline restarts). */
  applying: boolean;
  /** The Edit button: into edit mode, or out of it. */
  toggle(): void;
  leave(): void;
  /** The file and text the editor starts with (the draft kept, else the pipeline's). */
  file: string;
  text: string;
  onDraft(file: string, text: string): void;
  apply(file: string, text: string): ReturnType<Pipeline["loadSource"]>;
  /** The editor's notices (no block). */
  notify(m: string, level?: "info" | "error"): void;
}

export function useEditMode(pipeline: Pipeline, notify: Notify): EditMode {
  const current = useLatest(pipeline);
  const [editing, setEditing] = useState(false);
  const [applying, setApplying] = useState(false);
  const draft = useRef<{ file: string; text: string } | null>(null);
  const onDraft = useCallback((file: string, text: string) => {
    draft.current = { file, text };
  }, []);
  const apply = useCallback(async (file: string, text: string) => {
    setApplying(true);
    try {
      return await current.current.loadSource(file, text, true);
    } finally {
      setApplying(false);
    }
  }, []);
  const file = draft.current?.file ?? pipeline.file ?? EMPTY_FILE;
  const text = draft.current?.text ?? (pipeline.file !== undefined ? (pipeline.source ?? "") : "");
  const editingRef = useLatest(editing);
  useEffect(() => {
    if (!editingRef.current) draft.current = null;
  }, [pipeline.generation]);
  const leave = (): void => {
    setEditing(false);
    const d = draft.current;
    if (d && (d.text !== (pipeline.source ?? "") || d.file !== pipeline.file))
      notify("Edits not applied are kept: press Edit to go on with them");
    else draft.current = null;
  };
  const editorNotify = useCallback(
    (m: string, level?: "info" | "error") => notify(m, level),
    [notify],
  );
  const toggle = (): void => (editing ? leave() : setEditing(true));
  return { editing, applying, toggle, leave, file, text, onDraft, apply, notify: editorNotify };
}
