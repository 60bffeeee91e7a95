/**
 * What the editor has selected: a block (by name) or a connection (`to#index`), not both when
 * picked on the canvas. A block that vanished (undo, text edit) is no longer selected.
 */
import { useState } from "react";
import type { EditBlock } from "./model";

export interface EditorSelection {
  /** The selected block, when it is still in the text. */
  sel: EditBlock | undefined;
  /** The selected connection (`to#index`), or null. */
  selectedEdge: string | null;
  setSelected(name: string | null): void;
  setSelectedEdge(edge: string | null): void;
  /** The canvas picks a block (null: nothing): a connection is no longer selected. */
  selectBlock(name: string | null): void;
  /** The canvas picks a connection (null: nothing): a block is no longer selected. */
  selectEdge(edge: string | null): void;
}

export function useEditorSelection(blocks: readonly EditBlock[]): EditorSelection {
  const [selected, setSelected] = useState<string | null>(null);
  const [selectedEdge, setSelectedEdge] = useState<string | null>(null);
  const sel = selected !== null ? blocks.find((b) => b.name === selected) : undefined;
  return {
    sel,
    selectedEdge,
    setSelected,
    setSelectedEdge,
    selectBlock: (name) => {
      setSelected(name);
      if (name !== null) setSelectedEdge(null);
    },
    selectEdge: (edge) => {
      setSelectedEdge(edge);
      if (edge !== null) setSelected(null);
    },
  };
}
