/**
 * Completion in the text view, without CodeMirror (pure, tested): block types after `Type:`,
 * param names of the block's type inside `Params`, block keys, and block names in `Inputs`.
 */
import type { CatalogInfo } from "../../engine/protocol";
import type { JsonSchema } from "../forms/schema";
import { readBlocks, typeIndex, type EditBlock } from "./model";

export interface Completion {
  label: string;
  type: string;
  info?: string;
  detail?: string;
}

const BLOCK_KEYS: { label: string; info: string }[] = [
  { label: "Type", info: "The block type (see the palette)" },
  { label: "Inputs", info: "Blocks whose output this block receives: [Timer, Emg]" },
  { label: "Params", info: "The type's params: { Name: value }" },
  { label: "DesiredRate", info: "Hz; required for timers, else inherited from the inputs" },
  { label: "Path", info: "Log this block's output (a folder or a file)" },
  { label: "Layout", info: "Position on the canvas: { X: 0, Y: 0 }" },
  { label: "Worker", info: "Run this block on its own engine worker" },
  { label: "Queue", info: "Queue policy of its inputs" },
];

/** Completions at the cursor: types after `Type:`, params inside `Params`, keys, inputs. */
export function completeAt(
  text: string,
  pos: number,
  catalog: CatalogInfo | undefined,
): { from: number; options: Completion[] } | null {
  const lineStart = text.lastIndexOf("\n", pos - 1) + 1;
  const before = text.slice(lineStart, pos);
  const word = /[A-Za-z_][\w-]*$/.exec(before)?.[0] ?? "";
  const from = pos - word.length;
  const head = before.slice(0, before.length - word.length);
  if (/\bType:\s*$/.test(head)) return { from, options: typeOptions(catalog) };
  const lineNo = text.slice(0, lineStart).split("\n").length;
  const { blocks } = readBlocks(text);
  // The block the cursor is in: the last one that starts on or above its line.
  const here = [...blocks].reverse().find((b) => b.line > 0 && b.line <= lineNo);
  if (/\bInputs:\s*\[[^\]]*$/.test(head) || /^\s*-\s*$/.test(head)) {
    return { from, options: inputOptions(blocks, here) };
  }
  const params = paramOptions(here, catalog);
  if (/\bParams:\s*\{[^}]*$/.test(head)) return { from, options: params };
  // Block style: a key under `Params:` (indented deeper than it), or a key of the block.
  const indent = /^\s*/.exec(before)![0].length;
  if (here && /^\s*$/.test(head) && indent > 0) {
    const lines = text.slice(0, lineStart).split("\n");
    return { from, options: underParams(lines, here.line, indent) ? params : keyOptions() };
  }
  if (/[{,]\s*$/.test(head) && here) return { from, options: keyOptions() };
  return null;
}

/** Every block type of the catalog. */
function typeOptions(catalog: CatalogInfo | undefined): Completion[] {
  const types = catalog?.types ?? [];
  return types.map((t) => ({
    label: t.type,
    type: "class",
    detail: t.category,
    info: t.summary,
  }));
}

/** Every block name but the one the cursor is in. */
function inputOptions(blocks: EditBlock[], here: EditBlock | undefined): Completion[] {
  const names = blocks.map((b) => b.name);
  return names.filter((n) => n !== here?.name).map((n) => ({ label: n, type: "variable" }));
}

/** The param names of the type of the block the cursor is in (none outside a known type). */
function paramOptions(here: EditBlock | undefined, catalog: CatalogInfo | undefined): Completion[] {
  const t = here ? typeIndex(catalog).get(here.type) : undefined;
  return t
    ? Object.entries((t.paramsSchema as JsonSchema).properties ?? {}).map(([name, s]) => ({
        label: name,
        type: "property",
        ...(typeof s.description === "string" ? { info: s.description } : {}),
      }))
    : [];
}

/** The keys a block may have. */
function keyOptions(): Completion[] {
  return BLOCK_KEYS.map((k) => ({ ...k, type: "keyword" }));
}

/**
 * Whether the cursor's line, indented by `indent`, is under a `Params:` line: the nearest line
 * above it (from the block's first line, `blockLine`, 1-based) indented less than it.
 */
function underParams(lines: string[], blockLine: number, indent: number): boolean {
  for (let i = lines.length - 1; i >= blockLine - 1 && i >= 0; i--) {
    const l = lines[i]!;
    if (l.trim() === "" || l.trim().startsWith("#")) continue;
    const ind = /^\s*/.exec(l)![0].length;
    if (ind < indent) return /^\s*Params:\s*$/.test(l);
  }
  return false;
}
