/**
 * Edits of a pipeline file that keep everything else byte for byte (comments, key order, quoting,
 * flow or block style): node positions written back as `Layout: { X, Y }` keys, the canvas's
 * groups and comments as the pipeline's `Pipeline: { Layout }`, and a block's
 * param set to a new value. Both go through the editor's document model
 * (app/engine/pipeline/document.ts, via app/engine/protocol-document.ts), which rewrites only
 * the source ranges an edit touches.
 */
import {
  PipelineDocument,
  pipelineLayoutValue,
  type PipelineLayout,
} from "../../engine/protocol-document";

export interface Point {
  x: number;
  y: number;
}

/**
 * Returns `source` with the `Layout` of every block in `positions` set (rounded to whole pixels).
 * Blocks missing from the file are ignored. Throws when the file is not a YAML mapping.
 */
export function updateLayout(
  source: string,
  positions: ReadonlyMap<string, Point>,
  boxes?: PipelineLayout,
): string {
  const doc = PipelineDocument.parse(source, "");
  doc.setLayouts(positions);
  if (boxes) setBoxes(doc, boxes);
  return doc.toString();
}

/**
 * Writes the canvas's groups and comments as `Pipeline: { Layout: { Groups, Comments } }`
 * (app/engine/pipeline/pipeline-layout.ts); the text is left alone when they are what the file
 * already says, and the `Layout` key goes when there are none.
 */
function setBoxes(doc: PipelineDocument, boxes: PipelineLayout): void {
  const value = pipelineLayoutValue(boxes);
  const now = doc.setting("Layout");
  if (canonical(now) === canonical(value)) return;
  doc.setSetting("Layout", value);
}

/** JSON with every mapping's keys sorted (the file's key order does not count). */
function canonical(v: unknown): string {
  return JSON.stringify(v, (_k, x: unknown) =>
    x !== null && typeof x === "object" && !Array.isArray(x)
      ? Object.fromEntries(Object.entries(x).sort(([a], [b]) => (a < b ? -1 : a > b ? 1 : 0)))
      : x,
  );
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
