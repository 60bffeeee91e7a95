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
  ControlButton,
  Controls,
  Panel,
  ReactFlow,
  ReactFlowProvider,
  useNodesInitialized,
  useNodesState,
  useReactFlow,
  type NodeMouseHandler,
} from "@xyflow/react";
import { useCallback, useEffect, useMemo, useRef, useState } from "react";
import type { GraphInfo } from "../../engine/protocol";
import { useUi } from "../app/ui-context";
import { useLiveChanges } from "../app/use-live-values";
import { describeChanges } from "../editor/live-values";
import { BlockMenu } from "./block-menu";
import { BlockNode, GraphStateContext, type BlockNodeType, type GraphState } from "./block-node";
import { initialBoxes, rememberBoxes, type Boxes } from "./boxes";
import { LargeFlowTools } from "./large-flow-tools";
import { pipelinePositions } from "./layout-place";
import { updateLayout } from "./layout-yaml";
import { EdgeMarkerDefs, RateEdge, type RateEdgeType } from "./rate-edge";
import { ReadableZoom } from "./readable-zoom";
import { StatusIcon, STATUS_LABEL, type Status } from "./status";

const nodeTypes = { block: BlockNode };
/** Fit the pipeline, but never so small that it cannot be read (pan for the rest). */
const FIT = { padding: 0.08, minZoom: 0.5, maxZoom: 1.25 };
const edgeTypes = { rate: RateEdge };

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

/** Positions from the file's `Layout` keys, the automatic layout for blocks without one. */
export function graphPositions(
  graph: GraphInfo,
  ignoreFile = false,
): Map<string, { x: number; y: number }> {
  // Blocks without a Layout key among blocks with one go to free space (issue 17, defect 8).
  return pipelinePositions(
    graph.blocks.map((b) => ({
      name: b.name,
      inputs: b.inputs.map((i) => i.block),
      ...(!ignoreFile && b.layout ? { layout: { x: b.layout.x, y: b.layout.y } } : {}),
    })),
  );
}

function buildNodes(
  graph: GraphInfo,
  positions: Map<string, { x: number; y: number }>,
): BlockNodeType[] {
  const nodes = graph.blocks.map((b): BlockNodeType => ({
    id: b.name,
    type: "block",
    position: positions.get(b.name)!,
    data: { block: b },
    ariaLabel: `${b.name}, ${b.type}. Enter: control panel. Shift+F10: actions. Arrow keys: move.`,
    connectable: false,
    deletable: false,
  }));
  // Tab order follows the picture: left to right, then top to bottom.
  return nodes.sort((a, b) => a.position.x - b.position.x || a.position.y - b.position.y);
}

function buildEdges(graph: GraphInfo): RateEdgeType[] {
  const firstPort = new Map(graph.blocks.map((b) => [b.name, b.outputs[0]?.name]));
  return graph.blocks.flatMap((b) =>
    b.inputs.map((inp, i): RateEdgeType => ({
      id: `${b.name}#${i}`,
      type: "rate",
      source: inp.block,
      target: b.name,
      focusable: false,
      deletable: false,
      data: {
        from: inp.block,
        port: inp.port,
        showPort: firstPort.get(inp.block) !== inp.port,
        to: b.name,
        toIndex: i,
        subscribed: inp.subscribed,
      },
    })),
  );
}

/** Downloads `text` as a file named `name` (the browser cannot write files). */
export function download(name: string, text: string): void {
  const url = URL.createObjectURL(new Blob([text], { type: "text/yaml" }));
  const a = document.createElement("a");
  a.href = url;
  a.download = name;
  a.style.display = "none";
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 10_000);
}

function Legend() {
  const order: Status[] = ["ontime", "lagging", "stumbling", "idle"];
  return (
    <ul className="status-legend" aria-label="Status colours">
      {order.map((s) => (
        <li key={s} className={`status-legend__item status-${s}`}>
          <StatusIcon status={s} /> {STATUS_LABEL[s]}
        </li>
      ))}
    </ul>
  );
}

function Table(props: BlockTableProps) {
  const { graph, source, running, openPanels, reducedMotion } = props;
  const remembered = props.positions;
  const initial = useMemo(() => {
    const pos = graphPositions(graph);
    for (const [k, p] of remembered ?? []) if (pos.has(k)) pos.set(k, p);
    return buildNodes(graph, pos);
  }, [graph, remembered]);
  const edges = useMemo(() => buildEdges(graph), [graph]);
  const [nodes, setNodes, onNodesChange] = useNodesState<BlockNodeType>(initial);
  const flow = useReactFlow();
  const [menu, setMenu] = useState<{ block: string; anchor: { x: number; y: number } } | null>(
    null,
  );
  const focusBack = useRef<HTMLElement | null>(null);
  const byName = useMemo(() => new Map(graph.blocks.map((b) => [b.name, b])), [graph]);
  const names = useMemo(() => graph.blocks.map((b) => b.name), [graph]);
  // Group and comment boxes (Pipeline: { Layout }), kept across reloads as positions are.
  const [boxes, setBoxesNow] = useState<Boxes>(() => initialBoxes(graph));
  const setBoxes = useCallback(
    (b: Boxes) => {
      setBoxesNow(b);
      rememberBoxes(graph, b);
    },
    [graph],
  );

  const openMenu = useCallback((block: string, anchor: { x: number; y: number }) => {
    focusBack.current =
      document.activeElement instanceof HTMLElement ? document.activeElement : null;
    setMenu({ block, anchor });
  }, []);
  const closeMenu = useCallback(() => {
    setMenu(null);
    focusBack.current?.focus();
  }, []);

  const state = useMemo<GraphState>(
    () => ({ running, openPanels, onMenu: openMenu }),
    [running, openPanels, openMenu],
  );

  const onNodeClick: NodeMouseHandler<BlockNodeType> = (_e, node) => props.onTogglePanel(node.id);
  const onNodeContextMenu: NodeMouseHandler<BlockNodeType> = (e, node) => {
    e.preventDefault();
    openMenu(node.id, { x: e.clientX, y: e.clientY });
  };

  const onKeyDown = (e: React.KeyboardEvent<HTMLDivElement>): void => {
    const el = (e.target as HTMLElement).closest<HTMLElement>(".react-flow__node");
    const id = el?.dataset.id;
    if (!el || id === undefined || e.target !== el) return;
    if (e.key === "Enter") {
      e.preventDefault();
      props.onTogglePanel(id);
    } else if (e.key === "ContextMenu" || (e.key === "F10" && e.shiftKey)) {
      e.preventDefault();
      const r = el.getBoundingClientRect();
      openMenu(id, { x: r.left + 12, y: r.bottom + 4 });
    } else if (e.key.startsWith("Arrow") && !e.altKey && !e.ctrlKey && !e.metaKey) {
      // Arrow keys move the focused block (the keyboard's drag and drop); Shift: bigger steps.
      const step = e.shiftKey ? 50 : 10;
      const d = {
        ArrowLeft: [-step, 0],
        ArrowRight: [step, 0],
        ArrowUp: [0, -step],
        ArrowDown: [0, step],
      }[e.key];
      if (!d) return;
      e.preventDefault();
      setNodes((ns) =>
        ns.map((n) => {
          if (n.id !== id) return n;
          const position = { x: n.position.x + d[0]!, y: n.position.y + d[1]! };
          remembered?.set(id, position);
          return { ...n, position };
        }),
      );
    }
  };

  const duration = reducedMotion ? 0 : 300;

  /**
   * Shows the whole pipeline (zoom between FIT.minZoom and FIT.maxZoom). When even the smallest
   * zoom is too small, it starts at the left (where the signals come from) instead of the
   * middle, so that the first blocks are never cut.
   */
  const box = useRef<HTMLDivElement>(null);
  const fit = useCallback(
    (ms = 0) => {
      const el = box.current;
      const ns = flow.getNodes();
      if (!el || ns.length === 0) return;
      const b = flow.getNodesBounds(ns);
      const w = el.clientWidth;
      const h = el.clientHeight;
      const inner = 1 - 2 * FIT.padding;
      const z = Math.min((w * inner) / b.width, (h * inner) / b.height);
      const zoom = Math.max(FIT.minZoom, Math.min(FIT.maxZoom, z));
      const fitsX = b.width * zoom <= w * inner;
      const fitsY = b.height * zoom <= h * inner;
      const x = fitsX ? (w - b.width * zoom) / 2 - b.x * zoom : w * FIT.padding - b.x * zoom;
      const y = fitsY ? (h - b.height * zoom) / 2 - b.y * zoom : h * FIT.padding - b.y * zoom;
      void flow.setViewport({ x, y, zoom }, { duration: ms });
    },
    [flow],
  );

  // Fit once the nodes are measured, and again when the area changes size (a panel docked or
  // closed) until the user pans or zooms by hand.
  const userMoved = useRef(false);
  const initialized = useNodesInitialized();
  const [fitted, setFitted] = useState(false);
  useEffect(() => {
    if (initialized && !fitted) {
      fit();
      setFitted(true);
    }
  }, [initialized, fitted, fit]);
  useEffect(() => {
    const el = box.current;
    if (!el || typeof ResizeObserver !== "function") return undefined;
    let last = el.clientWidth * 10_000 + el.clientHeight;
    const ro = new ResizeObserver(() => {
      const size = el.clientWidth * 10_000 + el.clientHeight;
      if (size === last) return;
      last = size;
      if (!userMoved.current) fit();
    });
    ro.observe(el);
    return () => ro.disconnect();
  }, [fit]);

  const autoLayout = (): void => {
    const pos = graphPositions(graph, true);
    setNodes((ns) => ns.map((n) => ({ ...n, position: pos.get(n.id) ?? n.position })));
    remembered?.clear();
    userMoved.current = false;
    requestAnimationFrame(() => fit(duration));
  };

  const changes = useLiveChanges();
  const { writeLiveValues } = useUi();
  const saveLayout = (): void => {
    if (source === undefined) return;
    try {
      const positions = new Map(nodes.map((n) => [n.id, n.position]));
      const text = updateLayout(source, positions, boxes);
      const name = graph.file.split("/").pop() || "pipeline.yaml";
      download(name, text);
      // The layout only: live values changed since loaded are not in it, and it says so.
      const left =
        changes.length > 0
          ? `; not the live values (${describeChanges(changes)}): Write live values to keep them`
          : "";
      props.onNotify(`Saved the layout into ${name} (downloaded)${left}`);
    } catch (err) {
      props.onNotify(`Cannot save the layout: ${(err as Error).message}`, "error");
    }
  };

  const menuBlock = menu ? byName.get(menu.block) : undefined;

  return (
    <GraphStateContext.Provider value={state}>
      <div
        className={`block-table${fitted ? " is-fitted" : ""}`}
        ref={box}
        onKeyDown={onKeyDown}
        data-running={String(running)}
      >
        <EdgeMarkerDefs />
        <ReactFlow<BlockNodeType, RateEdgeType>
          nodes={nodes}
          edges={edges}
          nodeTypes={nodeTypes}
          edgeTypes={edgeTypes}
          onNodesChange={onNodesChange}
          onNodeDragStop={(_e, _n, moved) => {
            for (const n of moved) remembered?.set(n.id, { ...n.position });
          }}
          onNodeClick={onNodeClick}
          onNodeContextMenu={onNodeContextMenu}
          onPaneContextMenu={(e) => e.preventDefault()}
          nodesConnectable={false}
          elementsSelectable={false}
          nodesFocusable
          edgesFocusable={false}
          deleteKeyCode={null}
          selectionKeyCode={null}
          multiSelectionKeyCode={null}
          nodeClickDistance={5}
          onMoveStart={(e) => {
            // A user's pan or zoom has an event; fitView does not.
            if (e) userMoved.current = true;
          }}
          minZoom={0.2}
          maxZoom={2.5}
          aria-label="BlockTable: the pipeline's blocks and connections"
        >
          <ReadableZoom target={box} />
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
          <Controls showInteractive={false} showFitView={false} position="bottom-left">
            <ControlButton
              onClick={() => {
                userMoved.current = false;
                fit(duration);
              }}
              title="Show the whole pipeline"
              aria-label="Show the whole pipeline"
            >
              <svg viewBox="0 0 16 16" aria-hidden="true">
                <path
                  d="M1.5 5.5v-4h4M10.5 1.5h4v4M14.5 10.5v4h-4M5.5 14.5h-4v-4"
                  fill="none"
                  stroke="currentColor"
                  strokeWidth="1.8"
                />
              </svg>
            </ControlButton>
          </Controls>
          <Panel position="top-right" className="graph-actions">
            <button type="button" onClick={autoLayout} title="Arrange the blocks automatically">
              Auto layout
            </button>
            <button
              type="button"
              onClick={saveLayout}
              disabled={source === undefined}
              title="Download the pipeline file with the blocks' Layout positions updated (comments kept)"
            >
              Save layout…
            </button>
            {changes.length > 0 && writeLiveValues ? (
              <button
                type="button"
                className="graph-actions__write-live"
                onClick={writeLiveValues}
                title={`Write the live values changed since loading into the pipeline file (comments kept) and download it: ${describeChanges(changes, 10)}`}
              >
                Write live values ({changes.length})…
              </button>
            ) : null}
          </Panel>
          <Panel position="bottom-right">
            <Legend />
          </Panel>
        </ReactFlow>
        {menu && menuBlock ? (
          <BlockMenu
            block={menuBlock}
            anchor={menu.anchor}
            panelOpen={openPanels.has(menu.block)}
            onClose={closeMenu}
            onTogglePanel={() => props.onTogglePanel(menu.block)}
            onInvoke={(action, arg, label) => props.onInvoke(menu.block, action, arg, label)}
          />
        ) : null}
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
