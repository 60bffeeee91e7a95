/**
 * The pipeline's own layout, `Pipeline: { Layout: { Groups, Comments } }`: boxes drawn on the
 * BlockTable besides the blocks (whose positions are each block's `Layout: { X, Y }`). A group is
 * a titled box; a block whose box lies inside it moves with it (membership is the geometry, so
 * renaming or removing a block needs no edit here). A comment is a box of free text.
 *
 * ```yaml
 * Pipeline:
 *   Layout:
 *     Groups:
 *       - { Title: Acquisition, X: -24, Y: -48, Width: 440, Height: 260 }
 *     Comments:
 *       - { Text: "Band-pass, then rectify", X: 480, Y: 300, Width: 220, Height: 90 }
 * ```
 *
 * Read by the loader (stage 3, keys.ts: each bad value one positioned error), sent to the UI in
 * the graph, written by the UI through the document model (`PipelineDocument.setSetting`).
 */
import { isMap, isScalar, isSeq, type Node as YamlNode, type YAMLMap } from "yaml";
import { closest } from "../suggest";
import { Collector, describeNode, scalarString } from "./collector";

/** A box on the canvas, px (canvas coordinates, like a block's Layout). */
export interface LayoutBox {
  x: number;
  y: number;
  width: number;
  height: number;
}

export interface LayoutGroup extends LayoutBox {
  title: string;
}

export interface LayoutComment extends LayoutBox {
  text: string;
}

export interface PipelineLayout {
  groups: LayoutGroup[];
  comments: LayoutComment[];
}

/** At most this many groups and as many comments (a canvas needs a handful). */
export const MAX_LAYOUT_BOXES = 1000;
/** At most this many characters in a title or a comment. */
export const MAX_LAYOUT_TEXT = 10_000;

export const PIPELINE_LAYOUT_KEYS = ["Groups", "Comments"] as const;
const BOX_KEYS = ["X", "Y", "Width", "Height"] as const;

const EXPECTED_GROUP =
  "`{ Title: <text>, X: <number>, Y: <number>, Width: <number>, Height: <number> }`";
const EXPECTED_COMMENT =
  "`{ Text: <text>, X: <number>, Y: <number>, Width: <number>, Height: <number> }`";

/** `Pipeline: { Layout }`'s value; every problem is one positioned error. */
export function readPipelineLayout(c: Collector, node: unknown): PipelineLayout | undefined {
  if (!isMap(node)) {
    c.error("bad-layout", c.pos(node as YamlNode), `Pipeline: Layout is ${describeNode(node)}`, {
      expected: "a mapping with `Groups:` and/or `Comments:` lists",
    });
    return undefined;
  }
  const out: PipelineLayout = { groups: [], comments: [] };
  for (const it of (node as YAMLMap).items) {
    const k = scalarString(it.key) ?? "";
    if (k === "Groups")
      out.groups = readList(c, it.value, "Groups", "Title", EXPECTED_GROUP).map(
        ({ label, box }) => ({ title: label, ...box }),
      );
    else if (k === "Comments")
      out.comments = readList(c, it.value, "Comments", "Text", EXPECTED_COMMENT).map(
        ({ label, box }) => ({ text: label, ...box }),
      );
    else {
      const suggestion = closest(k, PIPELINE_LAYOUT_KEYS);
      c.error("bad-layout", c.pos(it.key as YamlNode), `Pipeline: unknown Layout key '${k}'`, {
        expected: `one of ${PIPELINE_LAYOUT_KEYS.join(", ")}`,
        ...(suggestion !== undefined ? { suggestion } : {}),
      });
    }
  }
  return out;
}

function readList(
  c: Collector,
  node: unknown,
  key: string,
  label: string,
  expected: string,
): { label: string; box: LayoutBox }[] {
  if (node === null || (isScalar(node) && node.value === null)) return [];
  if (!isSeq(node)) {
    c.error(
      "bad-layout",
      c.pos(node as YamlNode),
      `Pipeline: Layout ${key} is ${describeNode(node)}`,
      {
        expected: `a list of ${expected}`,
      },
    );
    return [];
  }
  if (node.items.length > MAX_LAYOUT_BOXES) {
    c.error(
      "bad-layout",
      c.pos(node as YamlNode),
      `Pipeline: Layout ${key} has ${node.items.length} items`,
      { expected: `at most ${MAX_LAYOUT_BOXES}` },
    );
    return [];
  }
  const out: { label: string; box: LayoutBox }[] = [];
  node.items.forEach((item, i) => {
    const read = readItem(c, item, `Pipeline: Layout ${key}[${i}]`, label, expected);
    if (read) out.push(read);
  });
  return out;
}

function readItem(
  c: Collector,
  item: unknown,
  where: string,
  label: string,
  expected: string,
): { label: string; box: LayoutBox } | undefined {
  if (!isMap(item)) {
    c.error("bad-layout", c.pos(item as YamlNode), `${where} is ${describeNode(item)}`, {
      expected,
    });
    return undefined;
  }
  const map = item as YAMLMap;
  const allowed = [label, ...BOX_KEYS];
  let ok = true;
  for (const it of map.items) {
    const k = scalarString(it.key) ?? "";
    if (allowed.includes(k)) continue;
    const suggestion = closest(k, allowed);
    c.error("bad-layout", c.pos(it.key as YamlNode), `${where}: unknown key '${k}'`, {
      expected: `one of ${allowed.join(", ")}`,
      ...(suggestion !== undefined ? { suggestion } : {}),
    });
    ok = false;
  }
  const text = readText(c, map, label, where);
  const nums = BOX_KEYS.map((k) => readNumber(c, map, k, where));
  if (!ok || text === undefined || nums.some((n) => n === undefined)) return undefined;
  const [x, y, width, height] = nums as number[];
  return { label: text, box: { x: x!, y: y!, width: width!, height: height! } };
}

function readText(c: Collector, map: YAMLMap, key: string, where: string): string | undefined {
  const pair = map.items.find((it) => scalarString(it.key) === key);
  if (!pair) return "";
  const v = isScalar(pair.value) ? pair.value.value : undefined;
  const s = v === null ? "" : typeof v === "number" || typeof v === "boolean" ? String(v) : v;
  if (typeof s === "string" && s.length <= MAX_LAYOUT_TEXT) return s;
  c.error(
    "bad-layout",
    c.pos(pair.value as YamlNode),
    `${where}: ${key} is ${describeNode(pair.value)}`,
    {
      expected: `text of at most ${MAX_LAYOUT_TEXT} characters`,
    },
  );
  return undefined;
}

function readNumber(c: Collector, map: YAMLMap, key: string, where: string): number | undefined {
  const pair = map.items.find((it) => scalarString(it.key) === key);
  const v = pair && isScalar(pair.value) ? pair.value.value : undefined;
  const size = key === "Width" || key === "Height";
  if (typeof v === "number" && Number.isFinite(v) && (!size || v > 0)) return v;
  c.error(
    "bad-layout",
    c.pos((pair?.value ?? map) as YamlNode),
    pair ? `${where}: ${key} is ${describeNode(pair.value)}` : `${where} has no ${key}`,
    { expected: size ? `a positive number of pixels` : "a number of pixels" },
  );
  return undefined;
}

/** The `Layout` value a `PipelineLayout` is written as (empty lists left out; undefined: none). */
export function pipelineLayoutValue(layout: PipelineLayout): Record<string, unknown> | undefined {
  const round = (b: LayoutBox) => ({
    X: Math.round(b.x),
    Y: Math.round(b.y),
    Width: Math.max(1, Math.round(b.width)),
    Height: Math.max(1, Math.round(b.height)),
  });
  const out: Record<string, unknown> = {};
  if (layout.groups.length > 0)
    out.Groups = layout.groups.map((g) => ({ Title: g.title, ...round(g) }));
  if (layout.comments.length > 0)
    out.Comments = layout.comments.map((m) => ({ Text: m.text, ...round(m) }));
  return Object.keys(out).length > 0 ? out : undefined;
}
