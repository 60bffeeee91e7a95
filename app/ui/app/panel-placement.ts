/**
 * A floating panel never covers the node that opened it (issue 17, defect 6): when it floats, when
 * its size changes and when the graph moves under it, a panel over its node moves beside it —
 * right, left, below or above, the first side where it fits in the graph's area, else where it
 * covers least of the node. Pure (no DOM): use-avoid-node.ts applies it to a panel.
 */
export interface Rect {
  x: number;
  y: number;
  width: number;
  height: number;
}

/** Space kept between the node and the panel, px. */
const GAP = 12;

const clamp = (v: number, lo: number, hi: number): number => Math.max(lo, Math.min(hi, v));

/** The area of `a` that `b` covers. */
export function overlapArea(a: Rect, b: Rect): number {
  const w = Math.min(a.x + a.width, b.x + b.width) - Math.max(a.x, b.x);
  const h = Math.min(a.y + a.height, b.y + b.height) - Math.max(a.y, b.y);
  return w > 0 && h > 0 ? w * h : 0;
}

/** A panel is not made narrower or lower than this to fit beside its node, px. */
export const MIN_PANEL = { width: 320, height: 220 };

export interface Placement {
  x: number;
  y: number;
  /** Set when the panel must be smaller to fit beside the node. */
  width?: number;
  height?: number;
}

/**
 * Where a panel of `size` at `current` goes so that it does not cover `node` (all in the area's
 * coordinates, the area `area` wide and high): `current` when it does not; else the first side
 * of the node (right, left, below, above) where it fits whole; else the side with the most room
 * when the panel, made smaller (not under MIN_PANEL), fits there; else, inside the area, where
 * it covers least of the node.
 */
export function placeBeside(
  node: Rect,
  current: { x: number; y: number },
  size: { width: number; height: number },
  area: { width: number; height: number },
): Placement {
  const at = (p: { x: number; y: number }): Rect => ({ ...p, ...size });
  if (overlapArea(node, at(current)) === 0) return current;
  const maxX = Math.max(0, area.width - size.width);
  const maxY = Math.max(0, area.height - size.height);
  const y = clamp(node.y, 0, maxY);
  const x = clamp(node.x, 0, maxX);
  const sides = [
    { x: node.x + node.width + GAP, y },
    { x: node.x - GAP - size.width, y },
    { x, y: node.y + node.height + GAP },
    { x, y: node.y - GAP - size.height },
  ];
  const fits = sides.find((p) => p.x >= 0 && p.y >= 0 && p.x <= maxX && p.y <= maxY);
  if (fits) return fits;
  const smaller = smallerBeside(node, size, area);
  if (smaller) return smaller;
  const clamped = sides.map((p) => ({ x: clamp(p.x, 0, maxX), y: clamp(p.y, 0, maxY) }));
  let best = clamped[0]!;
  for (const p of clamped) if (overlapArea(node, at(p)) < overlapArea(node, at(best))) best = p;
  return best;
}

/** The room right, left, below and above the node; the largest that holds MIN_PANEL. */
function smallerBeside(
  node: Rect,
  size: { width: number; height: number },
  area: { width: number; height: number },
): Placement | undefined {
  const w = Math.min(size.width, area.width);
  const h = Math.min(size.height, area.height);
  const y = clamp(node.y, 0, area.height - h);
  const x = clamp(node.x, 0, area.width - w);
  const right = area.width - (node.x + node.width + GAP);
  const left = node.x - GAP;
  const below = area.height - (node.y + node.height + GAP);
  const above = node.y - GAP;
  const options: (Placement & { room: number })[] = [
    { x: area.width - Math.min(w, right), y, width: Math.min(w, right), room: right * h },
    { x: left - Math.min(w, left), y, width: Math.min(w, left), room: left * h },
    { x, y: area.height - Math.min(h, below), height: Math.min(h, below), room: below * w },
    { x, y: above - Math.min(h, above), height: Math.min(h, above), room: above * w },
  ].filter((o) => (o.width ?? w) >= MIN_PANEL.width && (o.height ?? h) >= MIN_PANEL.height);
  if (options.length === 0) return undefined;
  const { room: _, ...best } = options.reduce((a, b) => (b.room > a.room ? b : a));
  return best;
}
