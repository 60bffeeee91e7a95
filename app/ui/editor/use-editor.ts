/**
 * The editor's state: the pipeline's text (the source of truth), its undo/redo history of text
 * snapshots and the blocks read from it (the last ones that parsed while the text does not); its
 * problems are the engine's (use-validation.ts). Canvas and inspector edits go through the document model (`edit`); the
 * text view replaces the text (`setText`); both end as a new text snapshot.
 */
import { useCallback, useMemo, useRef, useState } from "react";
import { parseDocumentText, type EditableDocument } from "./doc";
import { readBlocks, type EditBlock } from "./model";

const MAX_HISTORY = 200;
/** Typing in the text view within this time is one undo step. */
const COALESCE_MS = 800;

interface History {
  text: string;
  file: string;
  past: { text: string; file: string }[];
  future: { text: string; file: string }[];
}

export interface EditorModel {
  text: string;
  file: string;
  blocks: EditBlock[];
  /** True when the text does not parse (the canvas shows the last blocks that did). */
  broken: boolean;
  canUndo: boolean;
  canRedo: boolean;
  /** Applies a document edit; returns an error message when it was refused. */
  edit(op: (doc: EditableDocument) => void): string | undefined;
  setText(text: string): void;
  /** Starts over with another text (a template): undoable. */
  reset(text: string, file: string): void;
  undo(): void;
  redo(): void;
  freshName(base: string): string;
  /** The text right now (after edits not yet rendered). */
  textNow(): string;
}

export function useEditor(initialText: string, initialFile: string): EditorModel {
  const [h, setH] = useState<History>({
    text: initialText,
    file: initialFile,
    past: [],
    future: [],
  });
  const cur = useRef(h);
  cur.current = h;
  const lastTyped = useRef(0);

  const push = useCallback((text: string, file: string, coalesce = false) => {
    const p = cur.current;
    if (text === p.text && file === p.file) return;
    const past =
      coalesce && p.past.length > 0
        ? p.past
        : [...p.past, { text: p.text, file: p.file }].slice(-MAX_HISTORY);
    const next = { text, file, past, future: [] };
    cur.current = next;
    setH(next);
  }, []);

  const edit = useCallback(
    (op: (doc: EditableDocument) => void): string | undefined => {
      const p = cur.current;
      try {
        const doc = parseDocumentText(p.text, p.file);
        op(doc);
        lastTyped.current = 0;
        push(doc.toString(), p.file);
        return undefined;
      } catch (e) {
        return (e as Error).message;
      }
    },
    [push],
  );

  const setText = useCallback(
    (text: string) => {
      const now = Date.now();
      const coalesce = now - lastTyped.current < COALESCE_MS;
      lastTyped.current = now;
      push(text, cur.current.file, coalesce);
    },
    [push],
  );

  const reset = useCallback(
    (text: string, file: string) => {
      lastTyped.current = 0;
      push(text, file);
    },
    [push],
  );

  const undo = useCallback(() => {
    const p = cur.current;
    const prev = p.past.at(-1);
    if (!prev) return;
    lastTyped.current = 0;
    const next = {
      ...prev,
      past: p.past.slice(0, -1),
      future: [{ text: p.text, file: p.file }, ...p.future],
    };
    cur.current = next;
    setH(next);
  }, []);

  const redo = useCallback(() => {
    const p = cur.current;
    const n = p.future[0];
    if (!n) return;
    lastTyped.current = 0;
    const next = {
      ...n,
      past: [...p.past, { text: p.text, file: p.file }],
      future: p.future.slice(1),
    };
    cur.current = next;
    setH(next);
  }, []);

  const lastGood = useRef<EditBlock[]>([]);
  const read = useMemo(() => readBlocks(h.text), [h.text]);
  const broken = read.errors.length > 0;
  if (!broken) lastGood.current = read.blocks;
  const blocks = broken ? lastGood.current : read.blocks;

  const freshName = useCallback((base: string): string => {
    try {
      return parseDocumentText(cur.current.text, cur.current.file).freshName(base);
    } catch {
      /* the text does not parse: the names read from it */
    }
    const names = new Set(readBlocks(cur.current.text).blocks.map((b) => b.name));
    if (!names.has(base)) return base;
    for (let i = 2; ; i++) if (!names.has(`${base}${i}`)) return `${base}${i}`;
  }, []);

  return {
    text: h.text,
    file: h.file,
    blocks,
    broken,
    canUndo: h.past.length > 0,
    canRedo: h.future.length > 0,
    edit,
    setText,
    reset,
    undo,
    redo,
    freshName,
    textNow: () => cur.current.text,
  };
}
