/**
 * The BlockTable (paper III-B): the running pipeline as a graph, every block a node coloured by
 * its timing status, every input reference an edge labelled with its source's rate. Blocks are
 * placed by their `Layout` keys or by the automatic layered layout, can be dragged, and the
 * layout can be saved back into the pipeline file (a download: the browser cannot write files).
 *
 * Node and edge objects are built once per loaded graph; while running only the components read
 * telemetry (see block-node.tsx), so React Flow does not recompute anything at 20 Hz.
 */
import {
  Background,
  Panel,
  ReactFlow,
  ReactFlowProvider,
  type NodeMouseHandler,
} from "@xyflow/react";
import { useMemo } from "react";
import type { GraphInfo } from "../../engine/protocol";
import { useUi } from "../app/ui-context";
import { BlockNode, GraphStateContext, type BlockNodeType, type GraphState } from "./block-node";
import { FitControls, GraphActions, Legend, TableMenu } from "./block-table-parts";
import { LargeFlowTools } from "./large-flow-tools";
import { EdgeMarkerDefs, RateEdge, type RateEdgeType } from "./rate-edge";
import { ReadableZoom } from "./readable-zoom";
import {
  nodeKeyHandler,
  useBlockMenu,
  useBlockNodes,
  useBoxes,
  useLayoutActions,
} from "./use-block-table";
import { useFitView } from "./use-fit-view";

export { download, graphPositions } from "./block-table-model";

const nodeTypes = { block: BlockNode };
const edgeTypes = { rate: RateEdge };
/** A view of the pipeline only: nothing to connect, select or delete; blocks take the focus. */
const FLOW_OPTIONS = {
  nodesConnectable: false,
  elementsSelectable: false,
  nodesFocusable: true,
  edgesFocusable: false,
  deleteKeyCode: null,
  selectionKeyCode: null,
  multiSelectionKeyCode: null,
  nodeClickDistance: 5,
  minZoom: 0.2,
  maxZoom: 2.5,
} as const;

export interface BlockTableProps {
  graph: GraphInfo;
  /** The pipeline file's text, for "Save layout" (undefined: not available). */
  source: string | undefined;
  /**
   * Positions the user gave blocks (by dragging), kept by the host across reloads of the same
   * file; read at mount, updated after every drag.
   */
  positions?: Map<string, { x: number; y: number }>;
  running: boolean;
  openPanels: ReadonlySet<string>;
  reducedMotion: boolean;
  onTogglePanel(block: string): void;
  onInvoke(block: string, action: string, arg: unknown, label: string): void;
  onNotify(message: string, level?: "info" | "error"): void;
}

function Table(props: BlockTableProps) {
  const { graph, source, running, openPanels, reducedMotion } = props;
  const remembered = props.positions;
  const flow = useBlockNodes(graph, remembered);
  const { menu, openMenu, closeMenu, onNodeContextMenu } = useBlockMenu();
  const names = useMemo(() => graph.blocks.map((b) => b.name), [graph]);
  const [boxes, setBoxes] = useBoxes(graph);
  const state = useMemo<GraphState>(
    () => ({ running, openPanels, onMenu: openMenu }),
    [running, openPanels, openMenu],
  );
  const onNodeClick: NodeMouseHandler<BlockNodeType> = (_e, node) => props.onTogglePanel(node.id);
  const onKeyDown = nodeKeyHandler(props.onTogglePanel, openMenu, flow.setNodes, remembered);
  const duration = reducedMotion ? 0 : 300;
  const view = useFitView(duration);
  const { writeLiveValues } = useUi();
  const { autoLayout, saveLayout, changes } = useLayoutActions(props, flow, boxes, view);

  return (
    <GraphStateContext.Provider value={state}>
      <div
        className={`block-table${view.fitted ? " is-fitted" : ""}`}
        ref={view.box}
        onKeyDown={onKeyDown}
        data-running={String(running)}
      >
        <EdgeMarkerDefs />
        <ReactFlow<BlockNodeType, RateEdgeType>
          nodes={flow.nodes}
          edges={flow.edges}
          nodeTypes={nodeTypes}
          edgeTypes={edgeTypes}
          onNodesChange={flow.onNodesChange}
          onNodeDragStop={(_e, _n, moved) => {
            for (const n of moved) remembered?.set(n.id, { ...n.position });
          }}
          onNodeClick={onNodeClick}
          onNodeContextMenu={onNodeContextMenu}
          onPaneContextMenu={(e) => e.preventDefault()}
          onMoveStart={view.onMoveStart}
          {...FLOW_OPTIONS}
          aria-label="BlockTable: the pipeline's blocks and connections"
        >
          <ReadableZoom target={view.box} />
          <Background gap={24} size={1.2} />
          <LargeFlowTools
            names={names}
            boxes={boxes}
            onBoxes={setBoxes}
            onBlocksMoved={(moved) => {
              for (const [id, p] of moved) remembered?.set(id, { ...p });
            }}
            duration={duration}
          />
          <FitControls onFit={view.showAll} />
          <GraphActions
            canSave={source !== undefined}
            changes={changes}
            onAutoLayout={autoLayout}
            onSaveLayout={saveLayout}
            onWriteLiveValues={writeLiveValues}
          />
          <Panel position="bottom-right">
            <Legend />
          </Panel>
        </ReactFlow>
        <TableMenu
          graph={graph}
          menu={menu}
          openPanels={openPanels}
          onClose={closeMenu}
          onTogglePanel={props.onTogglePanel}
          onInvoke={props.onInvoke}
        />
      </div>
    </GraphStateContext.Provider>
  );
}

/** The BlockTable of one loaded graph (mount it with `key` = the load, to start fresh). */
export function BlockTable(props: BlockTableProps) {
  return (
    <ReactFlowProvider>
      <Table {...props} />
    </ReactFlowProvider>
  );
}
