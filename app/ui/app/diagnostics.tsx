/** The problems of a pipeline file: file:line:col, message, what was expected, a suggestion. */
import type { Diagnostic } from "../../engine/diagnostics";
import { countLevels, diagnosticLine, plural } from "./log-book";

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
  // Counted as the Log counts them (one line per diagnostic there).
  const { errors, warnings, infos: notes } = countLevels(diagnostics.map(diagnosticLine));
  const loaded = [
    ...(warnings > 0 || notes === 0 ? [plural(warnings, "warning")] : []),
    ...(notes > 0 ? [plural(notes, "note")] : []),
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
        {failed && errors > 0 ? ` — ${plural(errors, "error")}` : ""}
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
              {d.param !== undefined ? <code className="diagnostic__param">{d.param}</code> : null}
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
