/**
 * Live values against the file (issue 17, defect 1): which live params the engine runs with a
 * value other than the file's ("changed since loaded"), and writing those values back into the
 * pipeline's text through the document model (doc.ts): only the values change, comments and
 * formatting stay.
 */
import type { BlockInfo, GraphInfo } from "../../engine/protocol";
import { deepEqual } from "../forms/schema";
import { parseDocumentText, type EditableDocument } from "./doc";
import type { EditBlock } from "./model";

/** One live param whose engine value differs from the file's. */
export interface LiveChange {
  block: string;
  param: string;
  /** The engine's value. */
  value: unknown;
  /** The file's (undefined: the file does not set it). */
  file: unknown;
}

/** The live params of `block` whose engine value is not the file's (none when unknown). */
export function changedParams(block: BlockInfo): string[] {
  const file = block.fileParams;
  if (file === undefined) return [];
  return block.live.filter((p) => p in block.params && !deepEqual(block.params[p], file[p]));
}

/** Every live param of the graph changed since loaded, in block order. */
export function liveChanges(graph: GraphInfo | undefined): LiveChange[] {
  return (graph?.blocks ?? []).flatMap((b) =>
    changedParams(b).map((param) => ({
      block: b.name,
      param,
      value: b.params[param],
      file: b.fileParams?.[param],
    })),
  );
}

export interface WriteBack {
  /** The text with the values written. */
  text: string;
  /** The changes written. */
  written: LiveChange[];
  /** The changes that could not be written, each with the reason. */
  skipped: { change: LiveChange; reason: string }[];
}

/**
 * `text` with each change's value set as the block's `Params.<param>` (document model edits:
 * everything else byte for byte). A change that cannot be written (the block is not in the text,
 * MOSAIC's positional Params) is skipped with the reason; a text that does not parse throws.
 */
export function writeLiveValues(
  text: string,
  file: string,
  changes: readonly LiveChange[],
): WriteBack {
  const doc = parseDocumentText(text, file);
  const r = applyLiveValues(doc, changes);
  return { text: doc.toString(), ...r };
}

/** Sets each change's value in `doc` (see writeLiveValues); says which were written. */
export function applyLiveValues(
  doc: EditableDocument,
  changes: readonly LiveChange[],
): Omit<WriteBack, "text"> {
  const written: LiveChange[] = [];
  const skipped: WriteBack["skipped"] = [];
  for (const change of changes) {
    try {
      doc.setParam(change.block, change.param, change.value);
      written.push(change);
    } catch (e) {
      skipped.push({ change, reason: (e as Error).message });
    }
  }
  return { written, skipped };
}

/** Whether the text's block (as the editor reads it) has the change's value. */
function hasValue(blocks: readonly EditBlock[], c: LiveChange): boolean {
  const b = blocks.find((x) => x.name === c.block);
  return b !== undefined && deepEqual(b.params[c.param], c.value);
}

/** The changes whose value the text lacks (the editor offers to take them into it). */
export function missingFromText(
  changes: readonly LiveChange[],
  blocks: readonly EditBlock[],
): LiveChange[] {
  return changes.filter((c) => !hasValue(blocks, c));
}

/** The changes whose value the text has (saving it writes them to the file). */
export function presentInText(
  changes: readonly LiveChange[],
  blocks: readonly EditBlock[],
): LiveChange[] {
  return changes.filter((c) => hasValue(blocks, c));
}

/**
 * The changes of a pipeline loaded again (the same file: a fixed param edited, Start after it
 * finished, Simulate devices switched) that still apply to the new graph: the block has the live
 * param and the file's value of it did not change. The engine gets them again, so a reload does
 * not silently drop live values.
 */
export function keptChanges(
  changes: readonly LiveChange[],
  graph: GraphInfo | undefined,
): LiveChange[] {
  const by = new Map((graph?.blocks ?? []).map((b) => [b.name, b]));
  return changes.filter((c) => {
    const b = by.get(c.block);
    return (
      b !== undefined &&
      b.live.includes(c.param) &&
      b.fileParams !== undefined &&
      deepEqual(b.fileParams[c.param], c.file)
    );
  });
}

/** "Amplification.Value = 100, Emg.Gain = 2" (at most `max` named, then "and N more"). */
export function describeChanges(changes: readonly LiveChange[], max = 3): string {
  const named = changes
    .slice(0, max)
    .map((c) => `${c.block}.${c.param} = ${JSON.stringify(c.value)}`);
  const more = changes.length - named.length;
  return named.join(", ") + (more > 0 ? ` and ${more} more` : "");
}
