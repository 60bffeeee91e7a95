/**
 * The edit canvas's keys: Delete/Backspace remove the selected block or connection; on a focused
 * node Enter selects it and the arrow keys move it (10 px, 50 with Shift).
 */
import type { KeyboardEvent } from "react";
import type { BlockNodeType } from "../graph/block-node";

export interface CanvasKeysInput {
  nodes: readonly BlockNodeType[];
  selected: string | null;
  selectedEdge: string | null;
  onSelect(block: string | null): void;
  onMove(block: string, to: { x: number; y: number }): void;
  onDelete(): void;
}

/** How far an arrow key moves a node, or undefined for another key. */
function arrowStep(key: string, shift: boolean): readonly [number, number] | undefined {
  const step = shift ? 50 : 10;
  const steps: Record<string, readonly [number, number]> = {
    ArrowLeft: [-step, 0],
    ArrowRight: [step, 0],
    ArrowUp: [0, -step],
    ArrowDown: [0, step],
  };
  return steps[key];
}

export function useCanvasKeys(input: CanvasKeysInput): (e: KeyboardEvent<HTMLDivElement>) => void {
  const { nodes, selected, selectedEdge } = input;
  return (e) => {
    const el = (e.target as HTMLElement).closest<HTMLElement>(".react-flow__node");
    const id = el?.dataset.id;
    if ((e.key === "Delete" || e.key === "Backspace") && (selected || selectedEdge)) {
      e.preventDefault();
      input.onDelete();
      return;
    }
    if (!el || id === undefined || e.target !== el) return;
    if (e.key === "Enter") {
      e.preventDefault();
      input.onSelect(id);
    } else if (e.key.startsWith("Arrow") && !e.altKey && !e.ctrlKey && !e.metaKey) {
      const d = arrowStep(e.key, e.shiftKey);
      const n = nodes.find((x) => x.id === id);
      if (!d || !n) return;
      e.preventDefault();
      input.onMove(id, { x: n.position.x + d[0], y: n.position.y + d[1] });
    }
  };
}
