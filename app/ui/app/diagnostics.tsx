/** The problems of a pipeline file: file:line:col, message, what was expected, a suggestion. */
import type { Diagnostic } from "../../engine/diagnostics";

export function Diagnostics({
  diagnostics,
  error,
  failed,
}: {
  diagnostics: readonly Diagnostic[];
  error: string | undefined;
  /** The pipeline did not load (errors shown prominently). */
  failed: boolean;
}) {
  if (diagnostics.length === 0 && error === undefined) return null;
  const errors = diagnostics.filter((d) => d.severity === "error").length;
  const notes = diagnostics.filter((d) => d.severity === "info").length;
  const warnings = diagnostics.length - errors - notes;
  const count = (n: number, what: string): string => `${n} ${what}${n === 1 ? "" : "s"}`;
  const loaded = [
    ...(warnings > 0 || notes === 0 ? [count(warnings, "warning")] : []),
    ...(notes > 0 ? [count(notes, "note")] : []),
  ].join(" and ");
  return (
    <section
      className={`diagnostics${failed ? " is-failed" : ""}`}
      aria-label="Problems in the pipeline file"
      role={failed ? "alert" : undefined}
      data-diagnostics={diagnostics.length}
    >
      <h2>
        {failed ? "The pipeline did not load" : `${loaded} while loading`}
        {failed && errors > 0 ? ` — ${errors} error${errors === 1 ? "" : "s"}` : ""}
      </h2>
      {error !== undefined ? <p className="diagnostics__error">{error}</p> : null}
      <ul>
        {diagnostics.map((d, i) => (
          <li key={i} className={`diagnostic severity-${d.severity}`} data-severity={d.severity}>
            <span className="diagnostic__severity">{d.severity}</span>
            <code className="diagnostic__where">
              {d.line > 0 ? `${d.file}:${d.line}:${d.col}` : d.file}
            </code>
            <span className="diagnostic__message">
              {d.message}
              {d.expected !== undefined ? <> (expected {d.expected})</> : null}
            </span>
            {d.suggestion !== undefined ? (
              <span className="diagnostic__suggestion">
                did you mean <code>{d.suggestion}</code>?
              </span>
            ) : null}
          </li>
        ))}
      </ul>
    </section>
  );
}
