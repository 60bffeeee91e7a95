/**
 * MOSAIC's positional `Params` as the strings the loader hands to a block's `legacyParams`: one
 * per item of the flow list. `[ rest: 0;0;1 ]` (a one-pair mapping in YAML) is "rest:0;0;1".
 */
import { isMap, isScalar, isSeq, type YAMLSeq } from "yaml";

/** A scalar's value as a string (numbers and booleans as JS prints them, null as ""). */
export function scalarText(node: unknown): string | undefined {
  if (!isScalar(node)) return undefined;
  const v = node.value;
  if (v === null || v === undefined) return "";
  if (typeof v === "string") return v;
  if (typeof v === "number" || typeof v === "boolean") return String(v);
  return undefined;
}

/** One item of a positional list as a string. */
function itemText(item: unknown): string {
  const s = scalarText(item);
  if (s !== undefined) return s;
  if (isMap(item) && item.items.length === 1) {
    const p = item.items[0]!;
    return `${scalarText(p.key) ?? ""}:${scalarText(p.value) ?? ""}`;
  }
  if (isSeq(item)) return item.items.map((x) => scalarText(x) ?? "").join(";");
  return "";
}

/** The positional Params of a block, one string per item. */
export function positionalArgs(seq: YAMLSeq): string[] {
  return seq.items.map(itemText);
}
