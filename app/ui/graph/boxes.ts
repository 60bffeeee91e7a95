/**
 * The BlockTable's group and comment boxes (issue 17, "large flows"): the model behind
 * box-layer.tsx, pure (no React, no DOM). They are the pipeline file's `Pipeline: { Layout }`
 * (app/engine/pipeline/pipeline-layout.ts), written back by "Save layout…" (layout-yaml.ts).
 *
 * A group holds the blocks whose box lies inside its own when it starts to move (membership is
 * the picture, as Simulink's areas: nothing to keep in step when a block is renamed or removed).
 */
import type { GraphInfo } from "../../engine/protocol";
import type { LayoutBox, PipelineLayout } from "../../engine/pipeline/pipeline-layout";

export type Boxes = PipelineLayout;
export type BoxKind = "group" | "comment";

export const NO_BOXES: Boxes = { groups: [], comments: [] };

/** A new box's size, px (canvas). */
export const NEW_BOX = {
  group: { width: 420, height: 260 },
  comment: { width: 240, height: 110 },
} as const;
/** The smallest a box can be resized to, px (canvas). */
export const MIN_BOX = { width: 120, height: 60 };

export interface NodeRect {
  id: string;
  x: number;
  y: number;
  width: number;
  height: number;
}

/** The nodes whose whole box lies inside `box` (edges touching, within a pixel, count as inside). */
export function nodesInside(box: LayoutBox, nodes: readonly NodeRect[]): string[] {
  const e = 1;
  return nodes
    .filter(
      (n) =>
        n.x >= box.x - e &&
        n.y >= box.y - e &&
        n.x + n.width <= box.x + box.width + e &&
        n.y + n.height <= box.y + box.height + e,
    )
    .map((n) => n.id);
}

/** A box of `kind` whose top-left corner is `at` (canvas coordinates, whole pixels). */
export function newBox(kind: BoxKind, at: { x: number; y: number }): LayoutBox {
  return { x: Math.round(at.x), y: Math.round(at.y), ...NEW_BOX[kind] };
}

/** Replaces item `i` of `kind` by `f(item)`. */
export function updateBox(
  boxes: Boxes,
  kind: BoxKind,
  i: number,
  f: (b: LayoutBox & { title?: string; text?: string }) => Partial<LayoutBox> & {
    title?: string;
    text?: string;
  },
): Boxes {
  if (kind === "group") {
    return { ...boxes, groups: boxes.groups.map((g, k) => (k === i ? { ...g, ...f(g) } : g)) };
  }
  return { ...boxes, comments: boxes.comments.map((c, k) => (k === i ? { ...c, ...f(c) } : c)) };
}

/** Removes item `i` of `kind`. */
export function removeBox(boxes: Boxes, kind: BoxKind, i: number): Boxes {
  return kind === "group"
    ? { ...boxes, groups: boxes.groups.filter((_, k) => k !== i) }
    : { ...boxes, comments: boxes.comments.filter((_, k) => k !== i) };
}

/**
 * The boxes a BlockTable starts with: the file's, unless this page changed them since the same
 * file (same text of its Layout) was last shown — then those changes, as node positions are
 * remembered across reloads of a file (a param edit, Load again).
 */
interface Memory {
  file: string;
  fromFile: string;
  boxes: Boxes;
}
let memory: Memory | undefined;

export function initialBoxes(graph: GraphInfo): Boxes {
  const fromFile = JSON.stringify(graph.layout ?? NO_BOXES);
  if (memory && memory.file === graph.file && memory.fromFile === fromFile) return memory.boxes;
  memory = { file: graph.file, fromFile, boxes: graph.layout ?? NO_BOXES };
  return memory.boxes;
}

/** Keeps what the user did to the boxes of `graph` for its next BlockTable. */
export function rememberBoxes(graph: GraphInfo, boxes: Boxes): void {
  const fromFile = JSON.stringify(graph.layout ?? NO_BOXES);
  memory = { file: graph.file, fromFile, boxes };
}
