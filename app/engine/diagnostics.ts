/**
 * Diagnostics: every problem with a pipeline names the file, line and column, the block and the
 * parameter, says what was expected, and suggests the closest valid name for typos (DESIGN.md §2).
 */

/** `info`: what a stage did on request (a simulated device), neither a problem nor a risk. */
export type Severity = "error" | "warning" | "info";

export interface Diagnostic {
  severity: Severity;
  /** Short machine-readable code, e.g. "unknown-type", "yaml-syntax". */
  code: string;
  message: string;
  file: string;
  /** 1-based; 0 when the position is unknown. */
  line: number;
  /** 1-based; 0 when the position is unknown. */
  col: number;
  block?: string;
  param?: string;
  expected?: string;
  suggestion?: string;
}

/** `file:line:col: severity: text` as `mosaic validate` prints it. */
export function formatDiagnostic(d: Diagnostic): string {
  const where = d.line > 0 ? `${d.file}:${d.line}:${d.col}` : d.file;
  return `${where}: ${d.severity}: ${diagnosticText(d)}`;
}

/** The message with what was expected and the closest valid name (the editor shows this). */
export function diagnosticText(d: Diagnostic): string {
  let s = d.message;
  if (d.expected !== undefined) s += ` (expected ${d.expected})`;
  if (d.suggestion !== undefined) s += `; did you mean '${d.suggestion}'?`;
  return s;
}

/** Raised by block code at creation time for a bad parameter value that zod could not catch. */
export class BlockConfigError extends Error {
  constructor(
    message: string,
    readonly param?: string,
  ) {
    super(message);
    this.name = "BlockConfigError";
  }
}

export function errorMessage(e: unknown): string {
  if (e instanceof Error) return e.message;
  return String(e);
}
