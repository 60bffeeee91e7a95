/**
 * The editor's problems from the engine's \`validate\` replies (use-validation.ts), without React,
 * so that tests in the Node program can check them (a React import there brings @types/react's
 * global stubs of DOM elements into every Node test's types).
 */
import type { Diagnostic } from "../../engine/diagnostics";
import { diagnosticText } from "../../engine/protocol-diagnostics";
import type { Reply } from "../client/engine-client";
import type { EditIssue } from "./model";

/** A diagnostic as the editor lists it: the CLI's text, at its line and column. */
export function issueFromDiagnostic(d: Diagnostic): EditIssue {
  return {
    severity: d.severity === "error" ? "error" : "warning",
    message: diagnosticText(d),
    ...(d.block !== undefined ? { block: d.block } : {}),
    line: d.line,
    col: d.col,
  };
}

/** The problems in a `validate` reply (notes on what a stage did are not problems). */
export function issuesFromReply(r: Reply): EditIssue[] {
  if (!r.ok) {
    const why = r.message ?? "no reason given";
    return [
      {
        severity: "error",
        message: `the engine could not check the text: ${why}`,
        line: 0,
        col: 0,
      },
    ];
  }
  return (r.diagnostics ?? []).filter((d) => d.severity !== "info").map(issueFromDiagnostic);
}
