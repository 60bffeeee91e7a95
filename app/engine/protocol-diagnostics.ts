/**
 * How a diagnostic reads (app/engine/diagnostics.ts), re-exported under the protocol's name so
 * that the layering rule lets app/ui import it: the editor shows the words `mosaic validate`
 * prints (see tools/eslint-plugin-mosaic).
 */
export { diagnosticText, formatDiagnostic } from "./diagnostics";
