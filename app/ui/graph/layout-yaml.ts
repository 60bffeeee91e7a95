/**
 * Edits of a pipeline file that keep everything else byte for byte (comments, key order, quoting,
 * flow or block style): node positions written back as `Layout: { X, Y }` keys, and a block's
 * param set to a new value. Both go through the editor's document model
 * (app/engine/pipeline/document.ts, via app/engine/protocol-document.ts), which rewrites only
 * the source ranges an edit touches.
 */
import { PipelineDocument } from "../../engine/protocol-document";

export interface Point {
  x: number;
  y: number;
}

/**
 * Returns `source` with the `Layout` of every block in `positions` set (rounded to whole pixels).
 * Blocks missing from the file are ignored. Throws when the file is not a YAML mapping.
 */
export function updateLayout(source: string, positions: ReadonlyMap<string, Point>): string {
  const doc = PipelineDocument.parse(source, "");
  doc.setLayouts(positions);
  return doc.toString();
}

/**
 * Returns `source` with `Params.<param>` of `block` set to `value` (other lines untouched).
 * Throws when the block is missing or its Params are in MOSAIC's positional form.
 */
export function setBlockParam(
  source: string,
  block: string,
  param: string,
  value: unknown,
): string {
  const doc = PipelineDocument.parse(source, "");
  doc.setParam(block, param, value);
  return doc.toString();
}
