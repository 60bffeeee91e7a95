/**
 * The BlockTable's state: its nodes (placed, moved by drag or arrow keys), its group and comment
 * boxes, the actions menu of a block, and the layout buttons (Auto layout, Save layout…).
 */
import { useNodesState, type NodeMouseHandler } from "@xyflow/react";
import {
  useCallback,
  useMemo,
  useRef,
  useState,
  type Dispatch,
  type KeyboardEvent,
  type SetStateAction,
} from "react";
import type { GraphInfo } from "../../engine/protocol";
import { useLiveChanges } from "../app/use-live-values";
import type { LiveChange } from "../editor/live-values";
import { describeChanges } from "../editor/live-values";
import type { BlockNodeType } from "./block-node";
import type { BlockTableProps } from "./block-table";
import {
  buildEdges,
  buildNodes,
  download,
  graphPositions,
  type Positions,
} from "./block-table-model";
import { initialBoxes, rememberBoxes, type Boxes } from "./boxes";
import { updateLayout } from "./layout-yaml";
import type { RateEdgeType } from "./rate-edge";
import type { FitView } from "./use-fit-view";

type SetNodes = Dispatch<SetStateAction<BlockNodeType[]>>;

/** The nodes (at the remembered positions, else the file's or the automatic ones) and edges. */
export function useBlockNodes(graph: GraphInfo, remembered: Positions | undefined) {
  const initial = useMemo(() => {
    const pos = graphPositions(graph);
    for (const [k, p] of remembered ?? []) if (pos.has(k)) pos.set(k, p);
    return buildNodes(graph, pos);
  }, [graph, remembered]);
  const edges = useMemo<RateEdgeType[]>(() => buildEdges(graph), [graph]);
  const [nodes, setNodes, onNodesChange] = useNodesState<BlockNodeType>(initial);
  return { nodes, setNodes, onNodesChange, edges };
}

/** Group and comment boxes (Pipeline: { Layout }), kept across reloads as positions are. */
export function useBoxes(graph: GraphInfo): [Boxes, (b: Boxes) => void] {
  const [boxes, setBoxesNow] = useState<Boxes>(() => initialBoxes(graph));
  const setBoxes = useCallback(
    (b: Boxes) => {
      setBoxesNow(b);
      rememberBoxes(graph, b);
    },
    [graph],
  );
  return [boxes, setBoxes];
}

export interface MenuAt {
  block: string;
  anchor: { x: number; y: number };
}

/** A block's actions menu: open at a point, closed with the focus back where it was. */
export function useBlockMenu() {
  const [menu, setMenu] = useState<MenuAt | null>(null);
  const focusBack = useRef<HTMLElement | null>(null);
  const openMenu = useCallback((block: string, anchor: { x: number; y: number }) => {
    focusBack.current =
      document.activeElement instanceof HTMLElement ? document.activeElement : null;
    setMenu({ block, anchor });
  }, []);
  const closeMenu = useCallback(() => {
    setMenu(null);
    focusBack.current?.focus();
  }, []);
  const onNodeContextMenu: NodeMouseHandler<BlockNodeType> = (e, node) => {
    e.preventDefault();
    openMenu(node.id, { x: e.clientX, y: e.clientY });
  };
  return { menu, openMenu, closeMenu, onNodeContextMenu };
}

/** Arrow keys: how far the focused block moves (Shift: bigger steps); undefined: not an arrow. */
function arrowStep(e: KeyboardEvent<HTMLDivElement>): readonly [number, number] | undefined {
  const step = e.shiftKey ? 50 : 10;
  const d: Record<string, readonly [number, number]> = {
    ArrowLeft: [-step, 0],
    ArrowRight: [step, 0],
    ArrowUp: [0, -step],
    ArrowDown: [0, step],
  };
  return d[e.key];
}

/**
 * The keys of a focused block: Enter opens its control panel, the context menu key or Shift+F10
 * its actions, arrow keys move it (the keyboard's drag and drop).
 */
export function nodeKeyHandler(
  onTogglePanel: (block: string) => void,
  openMenu: (block: string, anchor: { x: number; y: number }) => void,
  setNodes: SetNodes,
  remembered: Positions | undefined,
): (e: KeyboardEvent<HTMLDivElement>) => void {
  return (e) => {
    const el = (e.target as HTMLElement).closest<HTMLElement>(".react-flow__node");
    const id = el?.dataset.id;
    if (!el || id === undefined || e.target !== el) return;
    if (e.key === "Enter") {
      e.preventDefault();
      onTogglePanel(id);
    } else if (e.key === "ContextMenu" || (e.key === "F10" && e.shiftKey)) {
      e.preventDefault();
      const r = el.getBoundingClientRect();
      openMenu(id, { x: r.left + 12, y: r.bottom + 4 });
    } else if (e.key.startsWith("Arrow") && !e.altKey && !e.ctrlKey && !e.metaKey) {
      const d = arrowStep(e);
      if (!d) return;
      e.preventDefault();
      setNodes((ns) =>
        ns.map((n) => {
          if (n.id !== id) return n;
          const position = { x: n.position.x + d[0], y: n.position.y + d[1] };
          remembered?.set(id, position);
          return { ...n, position };
        }),
      );
    }
  };
}

/** "Auto layout" (forgets the positions given by hand) and "Save layout…" (a download). */
export function useLayoutActions(
  props: Pick<BlockTableProps, "graph" | "source" | "positions" | "onNotify">,
  flow: { nodes: BlockNodeType[]; setNodes: SetNodes },
  boxes: Boxes,
  view: Pick<FitView, "showAllSoon">,
): { autoLayout(): void; saveLayout(): void; changes: LiveChange[] } {
  const { graph, source, positions: remembered, onNotify } = props;
  const changes = useLiveChanges();
  const autoLayout = (): void => {
    const pos = graphPositions(graph, true);
    flow.setNodes((ns) => ns.map((n) => ({ ...n, position: pos.get(n.id) ?? n.position })));
    remembered?.clear();
    view.showAllSoon();
  };
  const saveLayout = (): void => {
    if (source === undefined) return;
    try {
      const positions = new Map(flow.nodes.map((n) => [n.id, n.position]));
      const text = updateLayout(source, positions, boxes);
      const name = graph.file.split("/").pop() || "pipeline.yaml";
      download(name, text);
      // The layout only: live values changed since loaded are not in it, and it says so.
      const left =
        changes.length > 0
          ? `; not the live values (${describeChanges(changes)}): Write live values to keep them`
          : "";
      onNotify(`Saved the layout into ${name} (downloaded)${left}`);
    } catch (err) {
      onNotify(`Cannot save the layout: ${(err as Error).message}`, "error");
    }
  };
  return { autoLayout, saveLayout, changes };
}
