/**
 * MOSAIC's positional `Params` as the original's blocks received them: a list of strings, one per
 * item of the flow list, built from the source text of each scalar. The original read every item
 * as a string (YamlDotNet into `List<string>`), so `20.0` is "20.0" and `1.` is "1.", not the
 * numbers a typed YAML loader makes of them.
 *
 * `[ rest:   0;0;1 ]` and `[ algorithm: DirectControl ]` (a space after the colon) are one-pair
 * mappings in YAML; the original's blocks meant the string `key:value`, so such an item becomes
 * "rest:0;0;1" (key and value joined by the colon alone: see docs/mosaic-compatibility.md).
 */
import { isMap, isScalar, isSeq, type YAMLSeq } from "yaml";

/** A scalar as written: the source of a plain scalar, the value of a quoted one; null → "". */
export function scalarText(node: unknown): string | undefined {
  if (!isScalar(node)) return undefined;
  const v = node.value;
  if (v === null || v === undefined) return "";
  if (typeof v === "string") return v;
  return typeof node.source === "string" && node.source !== "" ? node.source : String(v);
}

/** One item of a positional list as the string the original's block received. */
function itemText(item: unknown): string {
  const s = scalarText(item);
  if (s !== undefined) return s;
  if (isMap(item) && item.items.length === 1) {
    const p = item.items[0]!;
    return `${itemText(p.key)}:${itemText(p.value)}`;
  }
  // A nested list `[1, 2]` is MOSAIC's vector `1;2`.
  if (isSeq(item)) return item.items.map(itemText).join(";");
  return "";
}

/** The positional Params of a block, one string per item (see the file comment). */
export function positionalArgs(seq: YAMLSeq): string[] {
  return seq.items.map(itemText);
}
