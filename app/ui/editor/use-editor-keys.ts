/**
 * The editor's shortcuts: Ctrl+Z / Ctrl+Shift+Z (Ctrl+Y) / Ctrl+D anywhere on the page while
 * editing, except in the inspector's fields (their own text undo).
 */
import { useEffect, useRef } from "react";

export interface EditorKeys {
  undo(): void;
  redo(): void;
  duplicate(): void;
}

function onEditorKey(e: KeyboardEvent, keys: EditorKeys): void {
  if (!(e.ctrlKey || e.metaKey) || e.altKey) return;
  const target = e.target as HTMLElement | null;
  if (target && (target.tagName === "INPUT" || target.tagName === "SELECT")) return;
  const k = e.key.toLowerCase();
  if (k === "z" && !e.shiftKey) keys.undo();
  else if ((k === "z" && e.shiftKey) || k === "y") keys.redo();
  else if (k === "d") keys.duplicate();
  else return;
  e.preventDefault();
}

/** `keys`: this render's actions (the listener, added once, calls the latest). */
export function useEditorKeys(keys: EditorKeys): void {
  const latest = useRef(keys);
  latest.current = keys;
  useEffect(() => {
    const onKey = (e: KeyboardEvent): void => onEditorKey(e, latest.current);
    window.addEventListener("keydown", onKey);
    return () => window.removeEventListener("keydown", onKey);
  }, []);
}
