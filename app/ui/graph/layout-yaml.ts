/**
 * Edits of a pipeline file that keep everything else byte for byte (comments, key order, quoting,
 * flow or block style): node positions written back as `Layout: { X, Y }` keys, and a block's
 * param set to a new value. The file is parsed with the `yaml` Document API, which gives the
 * source range of every node; only those ranges (or a new entry) are rewritten.
 */
import {
  isMap,
  isScalar,
  parseDocument,
  stringify,
  type Node as YamlNode,
  type Pair,
  type YAMLMap,
} from "yaml";

export interface Point {
  x: number;
  y: number;
}

interface Edit {
  start: number;
  end: number;
  text: string;
}

const num = (v: number): string => String(Math.round(v));
const flowLayout = (p: Point): string => `{ X: ${num(p.x)}, Y: ${num(p.y)} }`;

function keyOf(pair: Pair): unknown {
  return isScalar(pair.key) ? pair.key.value : pair.key;
}

/** Start of the line holding `offset`. */
function lineStart(src: string, offset: number): number {
  return src.lastIndexOf("\n", offset - 1) + 1;
}

/**
 * Returns `source` with the `Layout` of every block in `positions` set (rounded to whole pixels).
 * Blocks missing from the file are ignored. Throws when the file is not a YAML mapping.
 */
export function updateLayout(source: string, positions: ReadonlyMap<string, Point>): string {
  const doc = parseDocument(source);
  if (doc.errors.length > 0)
    throw new Error(`the pipeline file has YAML errors: ${doc.errors[0]!.message}`);
  const root = doc.contents;
  if (!isMap(root)) throw new Error("the pipeline file is not a mapping of blocks");
  const edits: Edit[] = [];
  for (const pair of root.items) {
    const name = keyOf(pair);
    if (typeof name !== "string") continue;
    const p = positions.get(name);
    const block = pair.value as YamlNode | null;
    if (!p || !isMap(block) || !block.range) continue;
    const layout = block.items.find((q) => keyOf(q) === "Layout")?.value as YamlNode | null;
    const xs = isMap(layout) ? layout.items.find((q) => keyOf(q) === "X")?.value : undefined;
    const ys = isMap(layout) ? layout.items.find((q) => keyOf(q) === "Y")?.value : undefined;
    if (isScalar(xs) && isScalar(ys) && xs.range && ys.range) {
      // Only the numbers change (whatever the style of the Layout mapping).
      edits.push({ start: xs.range[0], end: xs.range[1], text: num(p.x) });
      edits.push({ start: ys.range[0], end: ys.range[1], text: num(p.y) });
    } else {
      edits.push(setEntry(source, block, "Layout", flowLayout(p)));
    }
  }
  return apply(source, edits);
}

function apply(source: string, edits: Edit[]): string {
  edits.sort((a, b) => b.start - a.start);
  let out = source;
  for (const e of edits) out = out.slice(0, e.start) + e.text + out.slice(e.end);
  return out;
}

/** A new `key: value` entry at the end of a mapping, in the mapping's own style. */
function newEntry(source: string, map: YAMLMap, key: string, value: string): Edit {
  const entry = `${key}: ${value}`;
  if (map.flow) {
    const last = map.items[map.items.length - 1];
    const lastEnd = last ? ((last.value ?? last.key) as YamlNode | null)?.range?.[1] : undefined;
    if (lastEnd !== undefined) return { start: lastEnd, end: lastEnd, text: `, ${entry}` };
    // `{}`: write inside the braces.
    const open = source.indexOf("{", map.range![0]);
    return { start: open + 1, end: open + 1, text: ` ${entry} ` };
  }
  // Block mapping: a new line after its last entry, at the indentation of its keys.
  const first = map.items[0]?.key as YamlNode | undefined;
  const keyStart = first?.range?.[0] ?? map.range![0];
  const indent = " ".repeat(keyStart - lineStart(source, keyStart));
  const end = map.range![1];
  return end > 0 && source[end - 1] === "\n"
    ? { start: end, end, text: `${indent}${entry}\n` }
    : { start: end, end, text: `\n${indent}${entry}` };
}

/** Sets `key` of a mapping to `value` (YAML text): replaces the old value or adds an entry. */
function setEntry(source: string, map: YAMLMap, key: string, value: string): Edit {
  const pair = map.items.find((q) => keyOf(q) === key);
  if (!pair) return newEntry(source, map, key, value);
  const v = pair.value as YamlNode | null;
  if (v && v.range && !(isScalar(v) && v.value === null)) {
    const [start, end] = v.range;
    // A block collection's range ends with its last line break: keep it.
    const keepBreak = end > start && source[end - 1] === "\n";
    return { start, end, text: keepBreak ? `${value}\n` : value };
  }
  const k = pair.key as YamlNode;
  const at = k.range![1] + (source[k.range![1]] === ":" ? 1 : 0);
  return { start: at, end: at, text: ` ${value}` };
}

/** A value as one line of flow YAML (`[1, 2]`, `{ a: 1 }`, `abs`, `"0.5"`). */
export function flowYaml(value: unknown): string {
  return stringify(value, { collectionStyle: "flow", lineWidth: 0 }).trimEnd();
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
  const doc = parseDocument(source);
  if (doc.errors.length > 0)
    throw new Error(`the pipeline file has YAML errors: ${doc.errors[0]!.message}`);
  const root = doc.contents;
  if (!isMap(root)) throw new Error("the pipeline file is not a mapping of blocks");
  const pair = root.items.find((q) => keyOf(q) === block);
  const spec = pair?.value as YamlNode | null | undefined;
  if (!isMap(spec)) throw new Error(`the file has no block '${block}'`);
  const params = spec.items.find((q) => keyOf(q) === "Params")?.value as
    YamlNode | null | undefined;
  const text = flowYaml(value);
  if (params === undefined || params === null || (isScalar(params) && params.value === null)) {
    return apply(source, [setEntry(source, spec, "Params", `{ ${param}: ${text} }`)]);
  }
  if (!isMap(params)) {
    throw new Error(
      `the Params of '${block}' are in MOSAIC's positional form: edit the file to change them`,
    );
  }
  return apply(source, [setEntry(source, params, param, text)]);
}
