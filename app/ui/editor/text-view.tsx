/**
 * The pipeline's YAML beside the canvas (CodeMirror 6): syntax highlighting, completion of block
 * types, block keys, param names (from the engine's catalog) and input names, and the problems
 * inline (the engine's check of the text, as `mosaic validate` says it, and what an Apply added),
 * set as they arrive. Typing replaces the editor's
 * text, so the canvas follows whenever it parses; canvas edits replace what it shows. Undo and
 * redo are the editor's (one history for both sides). Problems are also listed under it;
 * clicking one puts the cursor on its line.
 */
import {
  autocompletion,
  type CompletionContext,
  type CompletionResult,
} from "@codemirror/autocomplete";
import { defaultKeymap, indentWithTab } from "@codemirror/commands";
import { yaml } from "@codemirror/lang-yaml";
import { defaultHighlightStyle, syntaxHighlighting } from "@codemirror/language";
import {
  linter,
  lintGutter,
  setDiagnostics,
  type Diagnostic as LintDiagnostic,
} from "@codemirror/lint";
import { Annotation, EditorState, type Extension } from "@codemirror/state";
import {
  EditorView,
  highlightActiveLine,
  highlightActiveLineGutter,
  keymap,
  lineNumbers,
} from "@codemirror/view";
import { useEffect, useRef, type ReactNode, type RefObject } from "react";
import type { CatalogInfo } from "../../engine/protocol";
import { completeAt } from "./completion";
import type { EditIssue } from "./model";

export interface TextViewProps {
  text: string;
  issues: readonly EditIssue[];
  catalog: CatalogInfo | undefined;
  onChange(text: string): void;
}

/** Marks the transactions that bring in a text from outside (not the user's typing). */
const External = Annotation.define<boolean>();

function lineOffset(state: EditorState, line: number, col: number): { from: number; to: number } {
  const n = Math.max(1, Math.min(state.doc.lines, line || 1));
  const l = state.doc.line(n);
  const from = Math.min(l.to, l.from + Math.max(0, col - 1));
  return { from, to: from < l.to ? l.to : from };
}

/** The positioned issues as CodeMirror's lint diagnostics. */
function lintOf(state: EditorState, issues: readonly EditIssue[]): LintDiagnostic[] {
  return issues
    .filter((i) => i.line > 0)
    .map((i) => {
      const { from, to } = lineOffset(state, i.line, i.col);
      return { from, to, severity: i.severity, message: i.message };
    });
}

/** What the editor's extensions read when they run: the props of the latest render. */
type Latest = RefObject<Pick<TextViewProps, "issues" | "catalog" | "onChange">>;

/** The view's extensions: YAML, completion and lint from `latest`, typing reported to `onChange`. */
function extensionsOf(latest: Latest): Extension[] {
  return [
    lineNumbers(),
    highlightActiveLineGutter(),
    highlightActiveLine(),
    yaml(),
    syntaxHighlighting(defaultHighlightStyle, { fallback: true }),
    autocompletion({
      override: [
        (ctx: CompletionContext): CompletionResult | null =>
          completeAt(ctx.state.doc.toString(), ctx.pos, latest.current.catalog),
      ],
    }),
    linter((ev): LintDiagnostic[] => lintOf(ev.state, latest.current.issues), {
      delay: 150,
    }),
    lintGutter(),
    keymap.of([...defaultKeymap, indentWithTab]),
    // Long lines wrap: the pane is narrow and never scrolls sideways (issue 17, defect 8).
    EditorView.lineWrapping,
    EditorView.contentAttributes.of({ "aria-label": "Pipeline YAML" }),
    EditorView.updateListener.of((u) => {
      if (!u.docChanged || u.transactions.some((t) => t.annotation(External))) return;
      latest.current.onChange(u.state.doc.toString());
    }),
  ];
}

/** Creates the CodeMirror view in `host` once (with the first text), destroyed on unmount. */
function useCodeMirrorView(
  host: RefObject<HTMLDivElement | null>,
  view: RefObject<EditorView | null>,
  text: string,
  latest: Latest,
): void {
  useEffect(() => {
    const el = host.current;
    if (!el) return undefined;
    const v = new EditorView({
      parent: el,
      state: EditorState.create({ doc: text, extensions: extensionsOf(latest) }),
    });
    view.current = v;
    return () => {
      v.destroy();
      view.current = null;
    };
    // Created once (with the first text); later texts follow in useExternalText.
  }, []);
}

/** The change that turns `old` into `text`: the span between their common prefix and suffix. */
function differingSpan(old: string, text: string): { from: number; to: number; insert: string } {
  let start = 0;
  while (start < old.length && start < text.length && old[start] === text[start]) start++;
  let endOld = old.length;
  let endNew = text.length;
  while (endOld > start && endNew > start && old[endOld - 1] === text[endNew - 1]) {
    endOld--;
    endNew--;
  }
  return { from: start, to: endOld, insert: text.slice(start, endNew) };
}

/** A text from elsewhere (a canvas edit, undo, a template): replace what differs. */
function useExternalText(view: RefObject<EditorView | null>, text: string): void {
  useEffect(() => {
    const v = view.current;
    if (!v) return;
    const old = v.state.doc.toString();
    if (old === text) return;
    v.dispatch({ changes: differingSpan(old, text), annotations: External.of(true) });
  }, [text]);
}

/** The engine's answer comes after the text changed: shown when it arrives. */
function useIssueDiagnostics(view: RefObject<EditorView | null>, issues: readonly EditIssue[]) {
  useEffect(() => {
    const v = view.current;
    if (v) v.dispatch(setDiagnostics(v.state, lintOf(v.state, issues)));
  }, [issues]);
}

/** Puts the cursor at a line and column, scrolled into view and focused. */
function goToPosition(v: EditorView | null, line: number, col: number): void {
  if (!v || line < 1) return;
  const { from } = lineOffset(v.state, line, col);
  v.dispatch({ selection: { anchor: from }, scrollIntoView: true });
  v.focus();
}

/** The pipeline's text in a CodeMirror view, with its problems listed under it. */
export function TextView({ text, issues, catalog, onChange }: TextViewProps): ReactNode {
  const host = useRef<HTMLDivElement>(null);
  const view = useRef<EditorView | null>(null);
  const latest = useRef({ issues, catalog, onChange });
  latest.current = { issues, catalog, onChange };
  useCodeMirrorView(host, view, text, latest);
  useExternalText(view, text);
  useIssueDiagnostics(view, issues);

  const goTo = (line: number, col: number): void => goToPosition(view.current, line, col);

  return (
    <section className="text-view" aria-label="Pipeline text (YAML)">
      <div className="text-view__code" ref={host} />
      {issues.length > 0 ? (
        <ul className="text-view__issues" aria-label="Problems in the text">
          {issues.map((i, k) => (
            <li key={k} className={`level-${i.severity}`}>
              <button
                type="button"
                onClick={() => goTo(i.line, i.col)}
                aria-label={i.line > 0 ? `Go to line ${i.line}` : "Position unknown"}
              >
                {i.line > 0 ? `${i.line}:${i.col}` : "–"}
              </button>{" "}
              {i.message}
            </li>
          ))}
        </ul>
      ) : null}
    </section>
  );
}
