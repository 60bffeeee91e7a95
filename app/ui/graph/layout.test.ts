import { describe, expect, it } from "vitest";
import {
  acyclicEdges,
  countCrossings,
  layeredLayout,
  longestPathLayers,
  type Placed,
} from "./layout";

const opts = { nodeWidth: 100, nodeHeight: 50, gapX: 50, gapY: 10 };

/** Crossings of the laid-out graph, from the positions (edges between adjacent layers only). */
function crossingsOf(
  pos: Map<string, { x: number; y: number; layer: number }>,
  edges: [string, string][],
): number {
  let c = 0;
  for (let a = 0; a < edges.length; a++) {
    for (let b = a + 1; b < edges.length; b++) {
      const [s1, t1] = edges[a]!;
      const [s2, t2] = edges[b]!;
      const p = (n: string) => pos.get(n)!;
      if (p(s1).layer !== p(s2).layer || p(t1).layer !== p(t2).layer) continue;
      const d1 = p(s1).y - p(s2).y;
      const d2 = p(t1).y - p(t2).y;
      if (d1 * d2 < 0) c++;
    }
  }
  return c;
}

describe("layeredLayout", () => {
  it("puts a chain left to right, one layer per block, on one line", () => {
    const pos = layeredLayout(
      ["A", "B", "C"],
      [
        ["A", "B"],
        ["B", "C"],
      ],
      opts,
    );
    expect([...pos.values()].map((p) => p.layer)).toEqual([0, 1, 2]);
    expect(pos.get("A")!.x).toBe(0);
    expect(pos.get("B")!.x).toBe(150);
    expect(pos.get("C")!.x).toBe(300);
    expect(new Set([...pos.values()].map((p) => p.y)).size).toBe(1);
  });

  it("layers by the longest path and pulls a source next to its first consumer", () => {
    // The demo pipeline: the decimator's timer path joins the envelope late.
    const nodes = ["Timer", "Emg", "Amp", "Rect", "LowPass", "Pace", "Env", "Dec", "Dev"];
    const edges: [string, string][] = [
      ["Timer", "Emg"],
      ["Emg", "Amp"],
      ["Amp", "Rect"],
      ["Rect", "LowPass"],
      ["Timer", "Pace"],
      ["LowPass", "Env"],
      ["Pace", "Env"],
      ["Env", "Dec"],
      ["Dec", "Dev"],
    ];
    const pos = layeredLayout(nodes, edges, opts);
    const layer = (n: string) => pos.get(n)!.layer;
    expect(layer("Timer")).toBe(0);
    expect(layer("Emg")).toBe(1);
    expect(layer("Pace")).toBe(1);
    expect(layer("LowPass")).toBe(4);
    expect(layer("Env")).toBe(5);
    expect(layer("Dev")).toBe(7);
    for (const [a, b] of edges) expect(layer(a)).toBeLessThan(layer(b));
    const g = layeredLayout(
      ["Late", "A", "B", "C"],
      [
        ["A", "B"],
        ["B", "C"],
        ["Late", "C"],
      ],
    );
    expect(g.get("Late")!.layer).toBe(1);
  });

  it("removes crossings by barycenter ordering", () => {
    // In file order, the second layer would be [d, c] under [a, b]: a→c, b→d cross.
    const nodes = ["a", "b", "d", "c"];
    const edges: [string, string][] = [
      ["a", "c"],
      ["b", "d"],
      ["a", "x"],
      ["b", "y"],
    ];
    const pos = layeredLayout([...nodes, "y", "x"], edges, opts);
    expect(crossingsOf(pos, edges)).toBe(0);

    // A K(3,3)-like bipartite tangle that has a crossing-free order.
    const n2 = ["s1", "s2", "s3", "t3", "t1", "t2"];
    const e2: [string, string][] = [
      ["s1", "t1"],
      ["s2", "t2"],
      ["s3", "t3"],
      ["s1", "t2"],
    ];
    expect(crossingsOf(layeredLayout(n2, e2, opts), e2)).toBe(0);
  });

  it("lays out feedback loops (cycles) without hanging and places every node", () => {
    const nodes = ["Timer", "A", "B", "C"];
    const edges: [string, string][] = [
      ["Timer", "A"],
      ["A", "B"],
      ["B", "C"],
      ["C", "A"],
      ["B", "B"],
    ];
    const pos = layeredLayout(nodes, edges, opts);
    expect(pos.size).toBe(4);
    expect(pos.get("A")!.layer).toBeLessThan(pos.get("B")!.layer);
    expect(pos.get("B")!.layer).toBeLessThan(pos.get("C")!.layer);
  });

  it("never overlaps two boxes, isolates included, and is deterministic", () => {
    const nodes = ["T", "A", "B", "C", "D", "E", "Lonely", "F"];
    const edges: [string, string][] = [
      ["T", "A"],
      ["T", "B"],
      ["T", "C"],
      ["A", "D"],
      ["B", "D"],
      ["C", "E"],
      ["T", "F"],
      ["E", "F"],
      ["Nope", "A"],
    ];
    const pos = layeredLayout(nodes, edges, opts);
    expect(pos.size).toBe(nodes.length);
    const boxes = [...pos.values()];
    for (let i = 0; i < boxes.length; i++) {
      for (let j = i + 1; j < boxes.length; j++) {
        const a = boxes[i]!;
        const b = boxes[j]!;
        const apart = Math.abs(a.x - b.x) >= 100 || Math.abs(a.y - b.y) >= 50;
        expect(apart).toBe(true);
      }
    }
    expect(layeredLayout(nodes, edges, opts)).toEqual(pos);
  });

  it("places exact coordinates: dummies take half a lane, layers are centred, first name wins", () => {
    // T→D spans four layers (three dummies); "A" is listed twice (the second is an isolated
    // node whose position the first "A" overwrites); "X" is unknown; E→E is a self loop.
    const nodes = ["T", "A", "B", "C", "D", "E", "A", "Solo"];
    const edges: [string, string][] = [
      ["T", "A"],
      ["T", "E"],
      ["A", "B"],
      ["B", "C"],
      ["C", "D"],
      ["T", "D"],
      ["E", "B"],
      ["E", "E"],
      ["D", "A"],
      ["X", "A"],
    ];
    const pos = layeredLayout(nodes, edges, opts);
    expect([...pos]).toEqual([
      ["T", { x: 0, y: 0, layer: 0, order: 0 }],
      ["A", { x: 150, y: 15, layer: 1, order: 0 }],
      ["Solo", { x: 0, y: 120, layer: 0, order: 2 }],
      ["E", { x: 150, y: 75, layer: 1, order: 1 }],
      ["B", { x: 300, y: 45, layer: 2, order: 0 }],
      ["C", { x: 450, y: 45, layer: 3, order: 0 }],
      ["D", { x: 600, y: 60, layer: 4, order: 0 }],
    ]);
  });

  it("keeps the initial depth-first order with no sweeps and improves it with sweeps", () => {
    const nodes = ["n0", "n1", "n2", "n3", "n4", "n5"];
    const edges: [string, string][] = [
      ["n2", "n4"],
      ["n0", "n2"],
      ["n2", "n3"],
      ["n0", "n4"],
    ];
    const col = (p: Map<string, Placed>) => [...p].map(([k, v]) => [k, v.layer, v.order, v.y]);
    expect(col(layeredLayout(nodes, edges, { sweeps: 0 }))).toEqual([
      ["n0", 0, 0, 0],
      ["n1", 0, 1, 120],
      ["n5", 0, 2, 240],
      ["n2", 1, 0, 90],
      ["n4", 2, 0, 60],
      ["n3", 2, 1, 180],
    ]);
    const swept = layeredLayout(nodes, edges);
    expect(col(swept)).toEqual([
      ["n0", 0, 0, 0],
      ["n1", 0, 1, 120],
      ["n5", 0, 2, 240],
      ["n2", 1, 0, 90],
      ["n3", 2, 0, 60],
      ["n4", 2, 1, 180],
    ]);
    expect(swept.get("n3")!.x).toBe(2 * (184 + 64));
  });

  it("handles an empty graph", () => {
    expect(layeredLayout([], []).size).toBe(0);
  });
});

describe("layout helpers", () => {
  it("acyclicEdges drops back edges only", () => {
    const g = acyclicEdges(3, [
      [0, 1],
      [1, 2],
      [2, 0],
    ]);
    expect(g.succ).toEqual([[1], [2], []]);
    expect(longestPathLayers(g)).toEqual([0, 1, 2]);
  });

  it("countCrossings counts pairs of crossing segments", () => {
    const succ = [[3], [2], [], []];
    expect(countCrossings([0, 1], [2, 3], succ)).toBe(1);
    expect(countCrossings([0, 1], [3, 2], succ)).toBe(0);
  });
});
