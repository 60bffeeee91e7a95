/**
 * MOSAIC's positional `Params` as the original's blocks received them: a list of strings, one per
 * item of the flow list, built from the source text of each scalar. The original read every item
 * as a string (YamlDotNet into `List<string>`), so `20.0` is "20.0" and `1.` is "1.", not the
 * numbers a typed YAML loader makes of them.
 *
 * `[ rest:   0;0;1 ]` and `[ algorithm: DirectControl ]` (a space after the colon) are one-pair
 * mappings in YAML; the original's blocks meant the string `key:value`, so such an item becomes
 * "rest:0;0;1" (key and value joined by the colon alone: see docs/mosaic-compatibility.md).
 *
 * Decimal commas: files from the original's de-DE era write `'0,7'` and
 * `'0,00002206;0,00004412;0,00002206'`. The original, parsing en-US, read the comma as a
 * thousands separator (7, 2206); we read the number the author meant (0.7, 0.00002206) and the
 * loader warns once per block with what was read (`decimalCommas`, `decimalCommaWarning`).
 */
import { isMap, isScalar, isSeq, type Node as YamlNode, type YAMLSeq } from "yaml";
import type { Collector } from "./collector";

/** A scalar as written: the source of a plain scalar, the value of a quoted one; null → "". */
export function scalarText(node: unknown): string | undefined {
  if (!isScalar(node)) return undefined;
  const v = node.value;
  if (v === null || v === undefined) return "";
  if (typeof v === "string") return v;
  return typeof node.source === "string" && node.source !== "" ? node.source : String(v);
}

/** One item of a positional list as the string the original's block received. */
function rawItemText(item: unknown): string {
  const s = scalarText(item);
  if (s !== undefined) return s;
  if (isMap(item) && item.items.length === 1) {
    const p = item.items[0]!;
    return `${rawItemText(p.key)}:${rawItemText(p.value)}`;
  }
  // A nested list `[1, 2]` is MOSAIC's vector `1;2`.
  if (isSeq(item)) return item.items.map(rawItemText).join(";");
  return "";
}

/** A number written with a decimal comma: `0,7`, `-1,9867`, `+3,5e-2`. */
const COMMA_NUMBER = /^[+-]?\d+,\d+(?:[eE][+-]?\d+)?$/;
/** A number as the original's en-US parsing accepted it (no comma). */
const PLAIN_NUMBER = /^[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?$/;
/** An optional `name:` in front of the numbers (a Trigger's label, a Function's operation). */
const LABEL = /^([^:;,]*[^:;,\d\s.+-][^:;,]*:)(.*)$/s;

/**
 * An item's numbers read with decimal commas: `0,7` → `0.7`, `0,00002206;0,00004412` →
 * `0.00002206;0.00004412`, `rest:0,5;0` → `rest:0.5;0`. Only items whose every `;`-separated
 * part is a number and at least one has a decimal comma change; undefined otherwise. `original`
 * is what the original MOSAIC read (the comma as a thousands separator: 7, 2206).
 */
export function decimalCommaItem(text: string): { read: string; original: string } | undefined {
  if (!text.includes(",")) return undefined;
  const m = LABEL.exec(text);
  const label = m ? m[1]! : "";
  const body = m ? m[2]! : text;
  const parts = body.split(";");
  let commas = 0;
  for (const part of parts) {
    const t = part.trim();
    if (COMMA_NUMBER.test(t)) commas++;
    else if (t !== "" && !PLAIN_NUMBER.test(t)) return undefined;
  }
  if (commas === 0) return undefined;
  const map = (f: (t: string) => string): string =>
    label + parts.map((p) => (COMMA_NUMBER.test(p.trim()) ? f(p.trim()) : p.trim())).join(";");
  return {
    read: map((t) => t.replace(",", ".")),
    original: map((t) => String(Number(t.replace(",", "")))),
  };
}

function itemText(item: unknown): string {
  const text = rawItemText(item);
  return decimalCommaItem(text)?.read ?? text;
}

/** The positional Params of a block, one string per item (see the file comment). */
export function positionalArgs(seq: YAMLSeq): string[] {
  return seq.items.map(itemText);
}

/** An item of a positional list written with decimal commas. */
export interface DecimalComma {
  /** 0-based position in the list. */
  index: number;
  node: YamlNode;
  written: string;
  /** What we read (and hand to the block). */
  read: string;
  /** What the original MOSAIC read (the comma as a thousands separator). */
  original: string;
}

/** The items of a positional list that have decimal commas. */
export function decimalCommas(seq: YAMLSeq): DecimalComma[] {
  const found: DecimalComma[] = [];
  seq.items.forEach((item, index) => {
    const written = rawItemText(item);
    const d = decimalCommaItem(written);
    if (d) found.push({ index, node: item as YamlNode, written, ...d });
  });
  return found;
}

/** ONE warning per block with decimal commas in its positional Params: what was read. */
export function decimalCommaWarning(c: Collector, block: string, seq: YAMLSeq): void {
  const found = decimalCommas(seq);
  if (found.length === 0) return;
  const items = found.map((d) => `'${d.written}' as ${d.read}`).join(", ");
  const originals = found.map((d) => d.original).join(", ");
  c.warn(
    "decimal-comma",
    c.pos(found[0]!.node),
    `block '${block}': Params with decimal commas read as the author meant: ${items} ` +
      `(the original MOSAIC parsed numbers en-US and read the comma as a thousands separator: ${originals})`,
    { block },
  );
}
