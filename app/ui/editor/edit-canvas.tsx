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
  useNodesState,
  useReactFlow,
  type Connection,
  type OnNodesChange,
} from "@xyflow/react";
import { useEffect, useMemo, type ReactNode } from "react";
import type { CatalogInfo, GraphInfo } from "../../engine/protocol";
import {
  BlockNode,
  GraphStateContext,
  type BlockNodeType,
  type GraphState,
} from "../graph/block-node";
import { EdgeMarkerDefs, RateEdge, type RateEdgeType } from "../graph/rate-edge";
import type { EditBlock, EditIssue } from "./model";
import { BLOCK_TYPE_MIME } from "./palette";
import { useCanvasFit } from "./use-canvas-fit";
import { useCanvasGraph } from "./use-canvas-graph";
import { useCanvasKeys } from "./use-canvas-keys";

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

function Canvas(props: EditCanvasProps): ReactNode {
  const { blocks, running } = props;
  const flow = useReactFlow();
  const built = useCanvasGraph(props);
  const [nodes, setNodes, onNodesChange] = useNodesState<BlockNodeType>(built.nodes);
  useEffect(() => setNodes(built.nodes), [built, setNodes]);
  useCanvasFit(blocks.length === 0, props.fitKey, nodes.length);

  const state = useMemo<GraphState>(
    () => ({ running, openPanels: NO_PANELS, onMenu: () => {} }),
    [running],
  );
  const onKeyDown = useCanvasKeys({ ...props, nodes });
  const onDrop = (e: React.DragEvent<HTMLDivElement>): void => {
    const type = e.dataTransfer.getData(BLOCK_TYPE_MIME);
    if (!type) return;
    e.preventDefault();
    const p = flow.screenToFlowPosition({ x: e.clientX, y: e.clientY });
    props.onAdd(type, { x: p.x - 60, y: p.y - 30 });
  };

  return (
    <GraphStateContext.Provider value={state}>
      <div
        className="block-table edit-canvas is-fitted"
        data-running={String(running)}
        onKeyDown={onKeyDown}
        onDragOver={onDragOver}
        onDrop={onDrop}
      >
        <EdgeMarkerDefs />
        <CanvasFlow {...props} nodes={nodes} edges={built.edges} onNodesChange={onNodesChange} />
        {blocks.length === 0 ? (
          <p className="edit-canvas__hint">
            Drag a block type from the palette here (or focus it and press Enter).
          </p>
        ) : null}
      </div>
    </GraphStateContext.Provider>
  );
}

/** A palette entry dragged over the canvas is copied there. */
function onDragOver(e: React.DragEvent<HTMLDivElement>): void {
  if (e.dataTransfer.types.includes(BLOCK_TYPE_MIME)) {
    e.preventDefault();
    e.dataTransfer.dropEffect = "copy";
  }
}

const isValidConnection = (c: Connection | RateEdgeType): boolean => c.source !== c.target;

interface CanvasFlowProps extends EditCanvasProps {
  nodes: BlockNodeType[];
  edges: RateEdgeType[];
  onNodesChange: OnNodesChange<BlockNodeType>;
}

/** The React Flow view of the document: nodes, edges and what clicks, drags and connects do. */
function CanvasFlow(props: CanvasFlowProps): ReactNode {
  return (
    <ReactFlow<BlockNodeType, RateEdgeType>
      nodes={props.nodes}
      edges={props.edges}
      nodeTypes={nodeTypes}
      edgeTypes={edgeTypes}
      onNodesChange={props.onNodesChange}
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
  );
}

export function EditCanvas(props: EditCanvasProps): ReactNode {
  return (
    <ReactFlowProvider>
      <Canvas {...props} />
    </ReactFlowProvider>
  );
}
