/**
 * Automatic layered layout of a pipeline graph (left → right), for files without `Layout` keys.
 * Pure and deterministic (same graph, same positions); no DOM.
 *
 * 1. Cycles (feedback loops are allowed in pipelines) are broken by ignoring the back edges a
 *    depth-first search finds, visiting nodes in file order.
 * 2. Layers by longest path from the sources; a source that feeds only later layers is pulled
 *    right, next to its first consumer (a DecimatorTimer's timer, a second input).
 * 3. Edges spanning several layers get one dummy node per crossed layer, so that long edges take
 *    part in the ordering and keep a lane of their own.
 * 4. Crossing reduction: alternating down and up sweeps ordering each layer by the barycenter of
 *    its neighbours in the previous layer; the order with the fewest crossings wins.
 * 5. Coordinates: x by layer, y by position in the layer, each layer centred vertically.
 */

export interface LayoutOptions {
  /** Node box size, px. */
  nodeWidth: number;
  nodeHeight: number;
  /** Space between layers (x) and between nodes of one layer (y), px. */
  gapX: number;
  gapY: number;
  /** Down+up sweep pairs of the crossing reduction. */
  sweeps: number;
}

export const DEFAULT_LAYOUT: LayoutOptions = {
  nodeWidth: 184,
  nodeHeight: 92,
  gapX: 64,
  gapY: 28,
  sweeps: 8,
};

export interface Placed {
  x: number;
  y: number;
  layer: number;
  /** Position within the layer (dummies included), 0 at the top. */
  order: number;
}

/** Edges as `[from, to]` node names; unknown names and self loops are ignored. */
export type LayoutEdge = readonly [string, string];

interface Graph {
  n: number;
  succ: number[][];
  pred: number[][];
}

/** Removes back edges (DFS from every node in input order) so what is left is acyclic. */
export function acyclicEdges(n: number, edges: readonly (readonly [number, number])[]): Graph {
  const out: number[][] = Array.from({ length: n }, () => []);
  for (const [a, b] of edges) if (a !== b && !out[a]!.includes(b)) out[a]!.push(b);
  const state = new Uint8Array(n); // 0 new, 1 on stack, 2 done
  const succ: number[][] = Array.from({ length: n }, () => []);
  const pred: number[][] = Array.from({ length: n }, () => []);
  for (let root = 0; root < n; root++) {
    if (state[root] !== 0) continue;
    // Iterative DFS: stack of [node, next successor index].
    const stack: [number, number][] = [[root, 0]];
    state[root] = 1;
    while (stack.length > 0) {
      const top = stack[stack.length - 1]!;
      const [v, i] = top;
      if (i >= out[v]!.length) {
        state[v] = 2;
        stack.pop();
        continue;
      }
      top[1] = i + 1;
      const w = out[v]![i]!;
      if (state[w] === 1) continue; // back edge: part of a cycle, ignored for layering
      succ[v]!.push(w);
      pred[w]!.push(v);
      if (state[w] === 0) {
        state[w] = 1;
        stack.push([w, 0]);
      }
    }
  }
  return { n, succ, pred };
}

/** Longest-path layers of an acyclic graph; sources feeding only later layers move right. */
export function longestPathLayers(g: Graph): number[] {
  const layer = new Array<number>(g.n).fill(0);
  const indeg = g.pred.map((p) => p.length);
  const queue: number[] = [];
  for (let v = 0; v < g.n; v++) if (indeg[v] === 0) queue.push(v);
  const topo: number[] = [];
  while (queue.length > 0) {
    const v = queue.shift()!;
    topo.push(v);
    for (const w of g.succ[v]!) {
      layer[w] = Math.max(layer[w]!, layer[v]! + 1);
      if (--indeg[w]! === 0) queue.push(w);
    }
  }
  // Sources (no predecessors) sit just before their earliest consumer.
  for (let k = topo.length - 1; k >= 0; k--) {
    const v = topo[k]!;
    if (g.pred[v]!.length > 0 || g.succ[v]!.length === 0) continue;
    let first = Infinity;
    for (const w of g.succ[v]!) first = Math.min(first, layer[w]!);
    layer[v] = Math.max(0, first - 1);
  }
  return layer;
}

/** Number of crossings between two adjacent layers' orders, given edges from upper to lower. */
export function countCrossings(
  upper: readonly number[],
  lower: readonly number[],
  succ: readonly (readonly number[])[],
): number {
  const posLower = new Map<number, number>();
  lower.forEach((v, i) => posLower.set(v, i));
  const segs: [number, number][] = [];
  upper.forEach((v, i) => {
    for (const w of succ[v]!) {
      const j = posLower.get(w);
      if (j !== undefined) segs.push([i, j]);
    }
  });
  let c = 0;
  for (let a = 0; a < segs.length; a++) {
    for (let b = a + 1; b < segs.length; b++) {
      const [i1, j1] = segs[a]!;
      const [i2, j2] = segs[b]!;
      if ((i1 < i2 && j1 > j2) || (i1 > i2 && j1 < j2)) c++;
    }
  }
  return c;
}

/** Node indices of the edges between known, distinct names (the first index of a repeated name). */
function indexEdges(nodes: readonly string[], edges: readonly LayoutEdge[]): [number, number][] {
  const index = new Map<string, number>();
  nodes.forEach((name, i) => {
    if (!index.has(name)) index.set(name, i);
  });
  const pairs: [number, number][] = [];
  for (const [a, b] of edges) {
    const i = index.get(a);
    const j = index.get(b);
    if (i !== undefined && j !== undefined && i !== j) pairs.push([i, j]);
  }
  return pairs;
}

/** Splits long edges: one dummy node per crossed layer (indices ≥ real, pushed to `layerOf`). */
function splitLongEdges(dag: Graph, layerOf: number[]): { succ: number[][]; pred: number[][] } {
  const real = dag.n;
  const succ: number[][] = dag.succ.map(() => []);
  const pred: number[][] = dag.succ.map(() => []);
  const link = (a: number, b: number): void => {
    succ[a]!.push(b);
    pred[b]!.push(a);
  };
  for (let v = 0; v < real; v++) {
    for (const w of dag.succ[v]!) {
      let prev = v;
      for (let l = layerOf[v]! + 1; l < layerOf[w]!; l++) {
        const d = layerOf.length;
        layerOf.push(l);
        succ.push([]);
        pred.push([]);
        link(prev, d);
        prev = d;
      }
      link(prev, w);
    }
  }
  return { succ, pred };
}

/** Initial order: depth-first from the sources in file order, so chains stay together. */
function initialOrder(
  real: number,
  layerOf: readonly number[],
  succ: readonly (readonly number[])[],
  pred: readonly (readonly number[])[],
): number[][] {
  const total = layerOf.length;
  const depth = total === 0 ? 0 : Math.max(...layerOf) + 1;
  const layers: number[][] = Array.from({ length: depth }, () => []);
  const seen = new Uint8Array(total);
  const visit = (v: number): void => {
    const stack = [v];
    while (stack.length > 0) {
      const x = stack.pop()!;
      if (seen[x]) continue;
      seen[x] = 1;
      layers[layerOf[x]!]!.push(x);
      for (let k = succ[x]!.length - 1; k >= 0; k--) stack.push(succ[x]![k]!);
    }
  };
  for (let v = 0; v < real; v++) if (pred[v]!.length === 0) visit(v);
  for (let v = 0; v < total; v++) visit(v);
  return layers;
}

/** Crossings summed over every pair of adjacent layers. */
function totalCrossings(ls: readonly number[][], succ: readonly (readonly number[])[]): number {
  let c = 0;
  for (let l = 0; l + 1 < ls.length; l++) c += countCrossings(ls[l]!, ls[l + 1]!, succ);
  return c;
}

/** Sorts layer `l` by the barycenter of each node's neighbours (`nbrs`) in the `ref` order. */
function reorderByBarycenter(
  ls: number[][],
  l: number,
  nbrs: readonly (readonly number[])[],
  ref: readonly number[],
): void {
  const pos = new Map<number, number>();
  ref.forEach((v, i) => pos.set(v, i));
  const cur = ls[l]!;
  const keyed = cur.map((v, i) => {
    const ps = nbrs[v]!.map((w) => pos.get(w)).filter((p): p is number => p !== undefined);
    // Nodes without neighbours there keep their place.
    const bc = ps.length > 0 ? ps.reduce((a, b) => a + b, 0) / ps.length : i;
    return { v, bc, i };
  });
  keyed.sort((a, b) => a.bc - b.bc || a.i - b.i);
  ls[l] = keyed.map((k) => k.v);
}

/** Crossing reduction: alternating down and up sweeps; the order with the fewest crossings wins. */
function reduceCrossings(
  layers: readonly number[][],
  succ: readonly (readonly number[])[],
  pred: readonly (readonly number[])[],
  sweeps: number,
): number[][] {
  const depth = layers.length;
  let best = layers.map((l) => [...l]);
  let bestC = totalCrossings(best, succ);
  const work = layers.map((l) => [...l]);
  for (let s = 0; s < sweeps && bestC > 0; s++) {
    for (let l = 1; l < depth; l++) reorderByBarycenter(work, l, pred, work[l - 1]!);
    let c = totalCrossings(work, succ);
    if (c < bestC) {
      bestC = c;
      best = work.map((l) => [...l]);
    }
    for (let l = depth - 2; l >= 0; l--) reorderByBarycenter(work, l, succ, work[l + 1]!);
    c = totalCrossings(work, succ);
    if (c < bestC) {
      bestC = c;
      best = work.map((l) => [...l]);
    }
  }
  return best;
}

/** Coordinates: x by layer, y by lane, each layer centred; a dummy lane is half a node's height. */
function placeCoordinates(
  best: readonly (readonly number[])[],
  nodes: readonly string[],
  o: LayoutOptions,
): Map<string, Placed> {
  const real = nodes.length;
  const pitch = o.nodeHeight + o.gapY;
  const heightOf = (v: number): number => (v < real ? pitch : pitch / 2);
  const columnHeight = best.map((l) => l.reduce((a, v) => a + heightOf(v), 0));
  const tallest = Math.max(0, ...columnHeight);
  const out = new Map<string, Placed>();
  best.forEach((l, li) => {
    let y = (tallest - columnHeight[li]!) / 2;
    l.forEach((v, order) => {
      if (v < real) {
        out.set(nodes[v]!, { x: li * (o.nodeWidth + o.gapX), y: Math.round(y), layer: li, order });
      }
      y += heightOf(v);
    });
  });
  return out;
}

/**
 * Lays out `nodes` (names, in file order) connected by `edges`. Returns the top-left corner of
 * every node's box.
 */
export function layeredLayout(
  nodes: readonly string[],
  edges: readonly LayoutEdge[],
  options: Partial<LayoutOptions> = {},
): Map<string, Placed> {
  const o = { ...DEFAULT_LAYOUT, ...options };
  const real = nodes.length;
  const dag = acyclicEdges(real, indexEdges(nodes, edges));
  const layerOf = longestPathLayers(dag);
  const { succ, pred } = splitLongEdges(dag, layerOf);
  const layers = initialOrder(real, layerOf, succ, pred);
  const best = reduceCrossings(layers, succ, pred, o.sweeps);
  return placeCoordinates(best, nodes, o);
}
