/**
 * Completion in the text view, without CodeMirror (pure, tested): block types after `Type:`,
 * param names of the block's type inside `Params`, block keys, and block names in `Inputs`.
 */
import type { CatalogInfo } from "../../engine/protocol";
import type { JsonSchema } from "../forms/schema";
import { readBlocks, typeIndex } from "./model";

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
  const types = catalog?.types ?? [];
  if (/\bType:\s*$/.test(head)) {
    return {
      from,
      options: types.map((t) => ({
        label: t.type,
        type: "class",
        detail: t.category,
        info: t.summary,
      })),
    };
  }
  const lineNo = text.slice(0, lineStart).split("\n").length;
  const { blocks } = readBlocks(text);
  const names = blocks.map((b) => b.name);
  // The block the cursor is in: the last one that starts on or above its line.
  const here = [...blocks].reverse().find((b) => b.line > 0 && b.line <= lineNo);
  if (/\bInputs:\s*\[[^\]]*$/.test(head) || /^\s*-\s*$/.test(head)) {
    return {
      from,
      options: names.filter((n) => n !== here?.name).map((n) => ({ label: n, type: "variable" })),
    };
  }
  const t = here ? typeIndex(catalog).get(here.type) : undefined;
  const params = t
    ? Object.entries((t.paramsSchema as JsonSchema).properties ?? {}).map(([name, s]) => ({
        label: name,
        type: "property",
        ...(typeof s.description === "string" ? { info: s.description } : {}),
      }))
    : [];
  if (/\bParams:\s*\{[^}]*$/.test(head)) return { from, options: params };
  // Block style: a key under `Params:` (indented deeper than it), or a key of the block.
  const lines = text.slice(0, lineStart).split("\n");
  const indent = /^\s*/.exec(before)![0].length;
  if (here && /^\s*$/.test(head) && indent > 0) {
    for (let i = lines.length - 1; i >= here.line - 1 && i >= 0; i--) {
      const l = lines[i]!;
      if (l.trim() === "" || l.trim().startsWith("#")) continue;
      const ind = /^\s*/.exec(l)![0].length;
      if (ind < indent) {
        if (/^\s*Params:\s*$/.test(l)) return { from, options: params };
        break;
      }
    }
    return { from, options: BLOCK_KEYS.map((k) => ({ ...k, type: "keyword" })) };
  }
  if (/[{,]\s*$/.test(head) && here) {
    return { from, options: BLOCK_KEYS.map((k) => ({ ...k, type: "keyword" })) };
  }
  return null;
}
