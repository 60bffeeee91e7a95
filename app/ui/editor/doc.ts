/**
 * The editor's access to the pipeline document model (app/engine/pipeline/document.ts, through
 * app/engine/protocol-document.ts): every canvas and inspector edit is one of its operations,
 * which change only what they touch in the file (comments, order and style kept).
 */
import { PipelineDocument } from "../../engine/protocol-document";

export type EditableDocument = PipelineDocument;

/** Parses a pipeline's text into an editable document; throws when the text does not parse. */
export function parseDocumentText(text: string, file: string): EditableDocument {
  return PipelineDocument.parse(text, file);
}
