/**
 * The BlockTable's nodes and edges, built once per loaded graph, where its blocks go (their
 * `Layout` keys or the automatic layout) and downloading the pipeline file with a new layout.
 */
import type { GraphInfo } from "../../engine/protocol";
import type { BlockNodeType } from "./block-node";
import { pipelinePositions } from "./layout-place";
import type { RateEdgeType } from "./rate-edge";

export type Positions = Map<string, { x: number; y: number }>;

/** Positions from the file's `Layout` keys, the automatic layout for blocks without one. */
export function graphPositions(graph: GraphInfo, ignoreFile = false): Positions {
  // Blocks without a Layout key among blocks with one go to free space (issue 17, defect 8).
  return pipelinePositions(
    graph.blocks.map((b) => ({
      name: b.name,
      inputs: b.inputs.map((i) => i.block),
      ...(!ignoreFile && b.layout ? { layout: { x: b.layout.x, y: b.layout.y } } : {}),
    })),
  );
}

export function buildNodes(graph: GraphInfo, positions: Positions): BlockNodeType[] {
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

export function buildEdges(graph: GraphInfo): RateEdgeType[] {
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
