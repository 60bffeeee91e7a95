/**
 * Where blocks without a position go when others already have one (issue 17, defect 8: a block
 * added in the YAML landed on top of another node). Blocks with a position (a `Layout` key, or
 * where the canvas already drew them) stay; each other block goes right of the inputs it reads
 * from (or where the automatic layout puts it, when none of them has a position), then to the
 * nearest spot where its box, with a margin, covers no other. Pure and deterministic; no DOM.
 */
import { DEFAULT_LAYOUT, layeredLayout } from "./layout";

export interface Point {
  x: number;
  y: number;
}

export interface Size {
  width: number;
  height: number;
}

/** Space kept free around a block placed here, px. */
const MARGIN = 16;
/** How far the search for a free spot goes, in steps of a node's half height / width. */
const MAX_RING = 40;

const NODE: Size = { width: DEFAULT_LAYOUT.nodeWidth, height: DEFAULT_LAYOUT.nodeHeight };

function covers(a: Point, b: Point, size: Size): boolean {
  return (
    a.x < b.x + size.width + MARGIN &&
    b.x < a.x + size.width + MARGIN &&
    a.y < b.y + size.height + MARGIN &&
    b.y < a.y + size.height + MARGIN
  );
}

/**
 * The free spot nearest `wanted` (itself when free): a box of `size` there covers none of the
 * boxes at `taken` (all of `size`), with a margin. Searched on a grid of half a node's size,
 * nearest first; down and right win ties.
 */
export function freeSpot(wanted: Point, taken: readonly Point[], size: Size = NODE): Point {
  const free = (p: Point): boolean => !taken.some((t) => covers(p, t, size));
  if (free(wanted)) return wanted;
  const dx = (size.width + MARGIN) / 2;
  const dy = (size.height + MARGIN) / 2;
  for (let ring = 1; ring <= MAX_RING; ring++) {
    const spots: (Point & { d: number })[] = [];
    for (let i = -ring; i <= ring; i++) {
      for (let j = -ring; j <= ring; j++) {
        if (Math.max(Math.abs(i), Math.abs(j)) !== ring) continue;
        const p = { x: wanted.x + i * dx, y: wanted.y + j * dy };
        // Distance on screen, then below before above and right before left.
        spots.push({
          ...p,
          d: (i * dx) ** 2 + (j * dy) ** 2 - (j > 0 ? 0.5 : 0) - (i > 0 ? 0.25 : 0),
        });
      }
    }
    spots.sort((a, b) => a.d - b.d);
    const hit = spots.find(free);
    if (hit) return { x: hit.x, y: hit.y };
  }
  // A very crowded canvas: below everything.
  return { x: wanted.x, y: Math.max(wanted.y, ...taken.map((t) => t.y + size.height + MARGIN)) };
}

export interface PlaceBlock {
  name: string;
  /** The blocks it reads from. */
  inputs: readonly string[];
  /** Its position when it already has one (a Layout key, a place on the canvas). */
  at?: Point;
}

/**
 * Positions for every block: those with `at` keep it; the others, in order, go right of the
 * inputs that have a position (at the height of the first), else to `auto`'s position, then to
 * the nearest free spot. When no block has a position, `auto` is used as it is.
 */
export function placeBlocks(
  blocks: readonly PlaceBlock[],
  auto: ReadonlyMap<string, Point>,
  size: Size = NODE,
): Map<string, Point> {
  const out = new Map<string, Point>();
  if (blocks.every((b) => b.at === undefined)) {
    for (const b of blocks) out.set(b.name, auto.get(b.name) ?? { x: 0, y: 0 });
    return out;
  }
  for (const b of blocks) if (b.at) out.set(b.name, b.at);
  for (const b of blocks) {
    if (b.at) continue;
    const from = b.inputs.map((i) => out.get(i)).filter((p): p is Point => p !== undefined);
    const wanted =
      from.length > 0
        ? {
            x: Math.max(...from.map((p) => p.x)) + size.width + DEFAULT_LAYOUT.gapX,
            y: from[0]!.y,
          }
        : (auto.get(b.name) ?? { x: 0, y: 0 });
    out.set(b.name, freeSpot(wanted, [...out.values()], size));
  }
  return out;
}

/**
 * A pipeline's positions: its blocks' `layout` (the file's Layout keys) where they have one, the
 * automatic layered layout when none has, else free space beside their inputs (placeBlocks).
 */
export function pipelinePositions(
  blocks: readonly { name: string; inputs: readonly string[]; layout?: Point }[],
): Map<string, Point> {
  const names = blocks.map((b) => b.name);
  const edges = blocks.flatMap((b) => b.inputs.map((i) => [i, b.name] as const));
  const auto = new Map<string, Point>();
  for (const [k, a] of layeredLayout(names, edges)) auto.set(k, { x: a.x, y: a.y });
  return placeBlocks(
    blocks.map((b) => ({ name: b.name, inputs: b.inputs, ...(b.layout ? { at: b.layout } : {}) })),
    auto,
  );
}
