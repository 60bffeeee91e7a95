/**
 * The editor's state: the pipeline's text (the source of truth), its undo/redo history of text
 * snapshots and the blocks read from it (the last ones that parsed while the text does not); its
 * problems are the engine's (use-validation.ts). Canvas and inspector edits go through the document model (`edit`); the
 * text view replaces the text (`setText`); both end as a new text snapshot.
 */
import { useCallback, useMemo, useRef, useState, type RefObject } from "react";
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

/** The history after a new snapshot (`coalesce`: the last undo step stays); undefined if same. */
function withSnapshot(
  p: History,
  text: string,
  file: string,
  coalesce: boolean,
): History | undefined {
  if (text === p.text && file === p.file) return undefined;
  const past =
    coalesce && p.past.length > 0
      ? p.past
      : [...p.past, { text: p.text, file: p.file }].slice(-MAX_HISTORY);
  return { text, file, past, future: [] };
}

/** The history one step back; undefined when there is nothing to undo. */
function steppedBack(p: History): History | undefined {
  const prev = p.past.at(-1);
  if (!prev) return undefined;
  return {
    ...prev,
    past: p.past.slice(0, -1),
    future: [{ text: p.text, file: p.file }, ...p.future],
  };
}

/** The history one step forward; undefined when there is nothing to redo. */
function steppedForward(p: History): History | undefined {
  const n = p.future[0];
  if (!n) return undefined;
  return {
    ...n,
    past: [...p.past, { text: p.text, file: p.file }],
    future: p.future.slice(1),
  };
}

/** A block name not in use: the document's, else one beside the names read from broken text. */
function freshNameIn(text: string, file: string, base: string): string {
  try {
    return parseDocumentText(text, file).freshName(base);
  } catch {
    /* the text does not parse: the names read from it */
  }
  const names = new Set(readBlocks(text).blocks.map((b) => b.name));
  if (!names.has(base)) return base;
  for (let i = 2; ; i++) if (!names.has(`${base}${i}`)) return `${base}${i}`;
}

type Push = (text: string, file: string, coalesce?: boolean) => void;

/** The history in state, its latest value in `cur`, the time of the last typing, and `push`. */
function useHistory(initialText: string, initialFile: string) {
  const [h, setH] = useState<History>({
    text: initialText,
    file: initialFile,
    past: [],
    future: [],
  });
  const cur = useRef(h);
  cur.current = h;
  const lastTyped = useRef(0);

  const push: Push = useCallback((text: string, file: string, coalesce = false) => {
    const next = withSnapshot(cur.current, text, file, coalesce);
    if (!next) return;
    cur.current = next;
    setH(next);
  }, []);
  return { h, setH, cur, lastTyped, push };
}

/** `edit`, `setText` and `reset`: each ends as a new snapshot (typing coalesced by time). */
function useTextChanges(cur: RefObject<History>, lastTyped: RefObject<number>, push: Push) {
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
    [cur, lastTyped, push],
  );

  const setText = useCallback(
    (text: string) => {
      const now = Date.now();
      const coalesce = now - lastTyped.current < COALESCE_MS;
      lastTyped.current = now;
      push(text, cur.current.file, coalesce);
    },
    [cur, lastTyped, push],
  );

  const reset = useCallback(
    (text: string, file: string) => {
      lastTyped.current = 0;
      push(text, file);
    },
    [lastTyped, push],
  );
  return { edit, setText, reset };
}

/** `undo` and `redo`: one snapshot back or forward (a typing's undo step ends there). */
function useUndoRedo(
  cur: RefObject<History>,
  lastTyped: RefObject<number>,
  setH: (next: History) => void,
) {
  const undo = useCallback(() => {
    const next = steppedBack(cur.current);
    if (!next) return;
    lastTyped.current = 0;
    cur.current = next;
    setH(next);
  }, [cur, lastTyped, setH]);

  const redo = useCallback(() => {
    const next = steppedForward(cur.current);
    if (!next) return;
    lastTyped.current = 0;
    cur.current = next;
    setH(next);
  }, [cur, lastTyped, setH]);
  return { undo, redo };
}

/** The blocks read from the text, or the last ones that parsed while it does not. */
function useBlocks(text: string): { blocks: EditBlock[]; broken: boolean } {
  const lastGood = useRef<EditBlock[]>([]);
  const read = useMemo(() => readBlocks(text), [text]);
  const broken = read.errors.length > 0;
  if (!broken) lastGood.current = read.blocks;
  return { blocks: broken ? lastGood.current : read.blocks, broken };
}

/** The editor's state and its operations: history, text changes, undo/redo and the blocks. */
export function useEditor(initialText: string, initialFile: string): EditorModel {
  const { h, setH, cur, lastTyped, push } = useHistory(initialText, initialFile);
  const { edit, setText, reset } = useTextChanges(cur, lastTyped, push);
  const { undo, redo } = useUndoRedo(cur, lastTyped, setH);
  const { blocks, broken } = useBlocks(h.text);
  const freshName = useCallback(
    (base: string): string => freshNameIn(cur.current.text, cur.current.file, base),
    [cur],
  );

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
