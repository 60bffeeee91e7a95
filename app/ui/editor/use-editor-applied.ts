/**
 * The text the engine runs, as far as the editor knows (the last Apply, or the text it started
 * with when a pipeline was loaded), and the problems shown: what `mosaic validate` says of the
 * text (the engine checks it), and what the last Apply of the same text added (a load
 * instantiates with the real devices' bridges).
 */
import { useMemo, useState } from "react";
import type { Diagnostic } from "../../engine/diagnostics";
import type { EditIssue } from "./model";
import type { EditorModel } from "./use-editor";
import { issueFromDiagnostic, type Validation } from "./use-validation";

export interface EditorApplied {
  issues: EditIssue[];
  /** How many of `issues` are errors. */
  errors: number;
  /** The text differs from the one that runs. */
  dirty: boolean;
  /** An Apply of `text` answered with these diagnostics. */
  setApplied(text: string, diagnostics: Diagnostic[]): void;
  /** The running pipeline has the text now too (live values): the applied text follows. */
  follow(): void;
}

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

/** `runs`: the text the engine runs when the editor opens (undefined: none, or not loaded). */
export function useEditorApplied(
  ed: EditorModel,
  check: Validation,
  runs: string | undefined,
): EditorApplied {
  const [applied, setApplied] = useState<{ text: string; diagnostics: Diagnostic[] }>({
    text: runs !== undefined ? runs : "\u0000",
    diagnostics: [],
  });
  const issues = useMemo(
    () =>
      applied.text === ed.text ? withApplied(check.issues, applied.diagnostics) : check.issues,
    [check.issues, ed.text, applied],
  );
  return {
    issues,
    errors: issues.filter((i) => i.severity === "error").length,
    dirty: applied.text !== ed.text,
    setApplied: (text, diagnostics) => setApplied({ text, diagnostics }),
    follow: () => setApplied((a) => ({ ...a, text: ed.textNow() })),
  };
}
