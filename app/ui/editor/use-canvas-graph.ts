/**
 * The edit canvas's nodes and edges, built from the editor's blocks (the document) and their
 * problems on every edit. A block without a `Layout` is placed once, beside what it reads from,
 * and stays there while others are added.
 */
import { useMemo, useRef } from "react";
import type { BlockInfo, CatalogInfo, GraphInfo } from "../../engine/protocol";
import type { BlockNodeType } from "../graph/block-node";
import { layeredLayout } from "../graph/layout";
import { placeBlocks } from "../graph/layout-place";
import type { RateEdgeType } from "../graph/rate-edge";
import { typeIndex, type EditBlock, type EditIssue } from "./model";

type Point = { x: number; y: number };

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

/** The problems' messages, per block. */
function issuesByBlock(issues: readonly EditIssue[]): Map<string, string[]> {
  const byBlock = new Map<string, string[]>();
  for (const i of issues) {
    if (i.block === undefined) continue;
    byBlock.set(i.block, [...(byBlock.get(i.block) ?? []), i.message]);
  }
  return byBlock;
}

/** Where each block goes: its Layout, where it was placed before, or free space (remembered). */
function blockPositions(
  blocks: readonly EditBlock[],
  names: ReadonlySet<string>,
  placed: Map<string, Point>,
): Map<string, Point> {
  const links = blocks.flatMap((b) =>
    b.inputs.filter((i) => names.has(i.block)).map((i) => [i.block, b.name] as const),
  );
  const auto = layeredLayout(
    blocks.map((b) => b.name),
    links,
  );
  // A block without a place yet goes to free space, beside what it reads from.
  return placeBlocks(
    blocks.map((b) => {
      const at = b.layout ?? placed.get(b.name);
      return { name: b.name, inputs: b.inputs.map((i) => i.block), ...(at ? { at } : {}) };
    }),
    auto,
  );
}

/** The edges: one per input that reads a block of the document. */
function blockEdges(
  blocks: readonly EditBlock[],
  names: ReadonlySet<string>,
  nodes: readonly BlockNodeType[],
  selectedEdge: string | null,
): RateEdgeType[] {
  const firstPort = new Map(nodes.map((n) => [n.id, n.data.block.outputs[0]?.name]));
  return blocks.flatMap((b) =>
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
}

export interface CanvasGraphInput {
  blocks: readonly EditBlock[];
  issues: readonly EditIssue[];
  catalog: CatalogInfo | undefined;
  graph: GraphInfo | undefined;
  selected: string | null;
  selectedEdge: string | null;
}

export function useCanvasGraph(input: CanvasGraphInput): {
  nodes: BlockNodeType[];
  edges: RateEdgeType[];
} {
  const { blocks, issues, catalog, graph, selected, selectedEdge } = input;
  // Where blocks without a Layout were placed: they stay there while others are added.
  const placed = useRef(new Map<string, Point>());

  return useMemo(() => {
    const names = new Set(blocks.map((b) => b.name));
    const positions = blockPositions(blocks, names, placed.current);
    const byBlock = issuesByBlock(issues);
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
    return { nodes, edges: blockEdges(blocks, names, nodes, selectedEdge) };
  }, [blocks, issues, catalog, graph, selected, selectedEdge]);
}
