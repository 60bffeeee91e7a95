/**
 * The canvas in edit mode: rebuilt from the editor's blocks (the document) and their problems on
 * every edit. Drop a palette entry to add a block, drag from an output handle to an input handle
 * to connect, select a block or an edge and press Delete to remove it, drag a block to move it
 * (its `Layout` key). While the pipeline runs the nodes show their status as in the BlockTable.
 */
import {
  Background,
  Controls,
  ReactFlow,
  ReactFlowProvider,
  useNodesInitialized,
  useNodesState,
  useReactFlow,
  type Connection,
} from "@xyflow/react";
import { useCallback, useEffect, useMemo, useRef, type ReactNode } from "react";
import type { BlockInfo, CatalogInfo, GraphInfo } from "../../engine/protocol";
import {
  BlockNode,
  GraphStateContext,
  type BlockNodeType,
  type GraphState,
} from "../graph/block-node";
import { layeredLayout } from "../graph/layout";
import { placeBlocks } from "../graph/layout-place";
import { EdgeMarkerDefs, RateEdge, type RateEdgeType } from "../graph/rate-edge";
import { typeIndex, type EditBlock, type EditIssue } from "./model";
import { BLOCK_TYPE_MIME } from "./palette";

const nodeTypes = { block: BlockNode };
const edgeTypes = { rate: RateEdge };
const NO_PANELS: ReadonlySet<string> = new Set();

export interface EditCanvasProps {
  blocks: readonly EditBlock[];
  issues: readonly EditIssue[];
  catalog: CatalogInfo | undefined;
  /** The loaded pipeline (rates, shapes and status of the blocks it has). */
  graph: GraphInfo | undefined;
  running: boolean;
  selected: string | null;
  selectedEdge: string | null;
  onSelect(block: string | null): void;
  onSelectEdge(edge: string | null): void;
  onAdd(type: string, at: { x: number; y: number }): void;
  onConnect(from: string, to: string): void;
  onMove(block: string, to: { x: number; y: number }): void;
  onDelete(): void;
  /** Changes when the whole pipeline was replaced (a template): the canvas fits it. */
  fitKey: number;
}

/** What a node shows of a block that is only in the document (so far). */
function blockInfo(
  b: EditBlock,
  catalog: CatalogInfo | undefined,
  graph: GraphInfo | undefined,
): BlockInfo {
  const t = typeIndex(catalog).get(b.type);
  const loaded = graph?.blocks.find((x) => x.name === b.name && x.type === (t?.type ?? b.type));
  return {
    name: b.name,
    type: t?.type ?? b.type,
    category: t?.category ?? "",
    summary: t?.summary ?? "",
    help: t?.help ?? "",
    worker: "main",
    timer: t?.timer ?? false,
    desiredRate: b.desiredRate ?? loaded?.desiredRate ?? 0,
    inputs: b.inputs.map((i) => ({ ...i })),
    outputs:
      loaded?.outputs ??
      (t?.outputs ?? ["out"]).map((name) => ({
        name,
        shape: { rows: 0, cols: 0 },
      })),
    views: t?.views ?? [],
    panel: "",
    live: t?.live ?? [],
    params: b.params,
    paramsSchema: t?.paramsSchema ?? {},
    actions: [],
    ...(b.layout ? { layout: b.layout } : {}),
    ...(b.path !== undefined ? { path: b.path } : {}),
  };
}

function Canvas(props: EditCanvasProps): ReactNode {
  const { blocks, issues, catalog, graph, running, selected, selectedEdge } = props;
  const flow = useReactFlow();
  // Where blocks without a Layout were placed: they stay there while others are added.
  const placed = useRef(new Map<string, { x: number; y: number }>());

  const built = useMemo(() => {
    const names = new Set(blocks.map((b) => b.name));
    const links = blocks.flatMap((b) =>
      b.inputs.filter((i) => names.has(i.block)).map((i) => [i.block, b.name] as const),
    );
    const auto = layeredLayout(
      blocks.map((b) => b.name),
      links,
    );
    const byBlock = new Map<string, string[]>();
    for (const i of issues) {
      if (i.block === undefined) continue;
      byBlock.set(i.block, [...(byBlock.get(i.block) ?? []), i.message]);
    }
    // A block without a place yet goes to free space, beside what it reads from.
    const positions = placeBlocks(
      blocks.map((b) => {
        const at = b.layout ?? placed.current.get(b.name);
        return { name: b.name, inputs: b.inputs.map((i) => i.block), ...(at ? { at } : {}) };
      }),
      auto,
    );
    const nodes = blocks.map((b): BlockNodeType => {
      const position = positions.get(b.name)!;
      placed.current.set(b.name, position);
      return {
        id: b.name,
        type: "block",
        position,
        data: { block: blockInfo(b, catalog, graph), edit: { issues: byBlock.get(b.name) ?? [] } },
        ariaLabel: `${b.name}, ${b.type}. Delete: remove. Arrow keys: move.`,
        selected: b.name === selected,
        deletable: false,
      };
    });
    const firstPort = new Map(nodes.map((n) => [n.id, n.data.block.outputs[0]?.name]));
    const edges = blocks.flatMap((b) =>
      b.inputs.flatMap((inp, i): RateEdgeType[] =>
        names.has(inp.block)
          ? [
              {
                id: `${b.name}#${i}`,
                type: "rate",
                source: inp.block,
                target: b.name,
                selected: `${b.name}#${i}` === selectedEdge,
                deletable: false,
                ariaLabel: `connection ${inp.source} to ${b.name}`,
                className: `${b.name}#${i}` === selectedEdge ? "is-selected" : "",
                data: {
                  from: inp.block,
                  port: inp.port || (firstPort.get(inp.block) ?? ""),
                  showPort: inp.port !== "" && firstPort.get(inp.block) !== inp.port,
                  to: b.name,
                  toIndex: i,
                  subscribed: inp.subscribed,
                },
              },
            ]
          : [],
      ),
    );
    return { nodes, edges };
  }, [blocks, issues, catalog, graph, selected, selectedEdge]);

  const [nodes, setNodes, onNodesChange] = useNodesState<BlockNodeType>(built.nodes);
  useEffect(() => setNodes(built.nodes), [built, setNodes]);

  // The pipeline is shown whole when the canvas opens and when it was replaced (a template);
  // never while blocks are added, so that a drop stays where it was dropped. Empty: zoom 1.
  const empty = blocks.length === 0;
  const { fitKey } = props;
  const fitPending = useRef(!empty);
  const lastFit = useRef(fitKey);
  if (lastFit.current !== fitKey) {
    lastFit.current = fitKey;
    fitPending.current = !empty;
  }
  const initialized = useNodesInitialized();
  useEffect(() => {
    if (empty) void flow.setViewport({ x: 40, y: 40, zoom: 1 });
  }, [empty, flow]);
  useEffect(() => {
    if (!fitPending.current || !initialized || nodes.length === 0) return;
    fitPending.current = false;
    void flow.fitView({ padding: 0.15, maxZoom: 1 });
  }, [initialized, nodes.length, flow, fitKey]);

  const state = useMemo<GraphState>(
    () => ({ running, openPanels: NO_PANELS, onMenu: () => {} }),
    [running],
  );

  const onDrop = (e: React.DragEvent<HTMLDivElement>): void => {
    const type = e.dataTransfer.getData(BLOCK_TYPE_MIME);
    if (!type) return;
    e.preventDefault();
    const p = flow.screenToFlowPosition({ x: e.clientX, y: e.clientY });
    props.onAdd(type, { x: p.x - 60, y: p.y - 30 });
  };

  const isValidConnection = useCallback(
    (c: Connection | RateEdgeType) => c.source !== c.target,
    [],
  );

  const onKeyDown = (e: React.KeyboardEvent<HTMLDivElement>): void => {
    const el = (e.target as HTMLElement).closest<HTMLElement>(".react-flow__node");
    const id = el?.dataset.id;
    if ((e.key === "Delete" || e.key === "Backspace") && (selected || selectedEdge)) {
      e.preventDefault();
      props.onDelete();
      return;
    }
    if (!el || id === undefined || e.target !== el) return;
    if (e.key === "Enter") {
      e.preventDefault();
      props.onSelect(id);
    } else if (e.key.startsWith("Arrow") && !e.altKey && !e.ctrlKey && !e.metaKey) {
      const step = e.shiftKey ? 50 : 10;
      const d = {
        ArrowLeft: [-step, 0],
        ArrowRight: [step, 0],
        ArrowUp: [0, -step],
        ArrowDown: [0, step],
      }[e.key];
      const n = nodes.find((x) => x.id === id);
      if (!d || !n) return;
      e.preventDefault();
      props.onMove(id, { x: n.position.x + d[0]!, y: n.position.y + d[1]! });
    }
  };

  return (
    <GraphStateContext.Provider value={state}>
      <div
        className="block-table edit-canvas is-fitted"
        data-running={String(running)}
        onKeyDown={onKeyDown}
        onDragOver={(e) => {
          if (e.dataTransfer.types.includes(BLOCK_TYPE_MIME)) {
            e.preventDefault();
            e.dataTransfer.dropEffect = "copy";
          }
        }}
        onDrop={onDrop}
      >
        <EdgeMarkerDefs />
        <ReactFlow<BlockNodeType, RateEdgeType>
          nodes={nodes}
          edges={built.edges}
          nodeTypes={nodeTypes}
          edgeTypes={edgeTypes}
          onNodesChange={onNodesChange}
          onNodeDragStop={(_e, n) => props.onMove(n.id, n.position)}
          onNodeClick={(_e, n) => props.onSelect(n.id)}
          onEdgeClick={(_e, edge) => props.onSelectEdge(edge.id)}
          onPaneClick={() => {
            props.onSelect(null);
            props.onSelectEdge(null);
          }}
          onConnect={(c) => props.onConnect(c.source, c.target)}
          isValidConnection={isValidConnection}
          nodesConnectable
          elementsSelectable={false}
          nodesFocusable
          edgesFocusable={false}
          deleteKeyCode={null}
          selectionKeyCode={null}
          multiSelectionKeyCode={null}
          nodeClickDistance={5}
          connectionRadius={30}
          minZoom={0.2}
          maxZoom={2.5}
          aria-label="Pipeline editor canvas: drop blocks here, drag from an output to an input to connect"
        >
          <Background gap={24} size={1.2} />
          <Controls showInteractive={false} position="bottom-left" />
        </ReactFlow>
        {blocks.length === 0 ? (
          <p className="edit-canvas__hint">
            Drag a block type from the palette here (or focus it and press Enter).
          </p>
        ) : null}
      </div>
    </GraphStateContext.Provider>
  );
}

export function EditCanvas(props: EditCanvasProps): ReactNode {
  return (
    <ReactFlowProvider>
      <Canvas {...props} />
    </ReactFlowProvider>
  );
}
