import { describe, expect, test } from "vitest";
import { DEFAULT_LAYOUT } from "./layout";
import { freeSpot, pipelinePositions, placeBlocks, type Point } from "./layout-place";

const W = DEFAULT_LAYOUT.nodeWidth;
const H = DEFAULT_LAYOUT.nodeHeight;

/** Whether two node boxes overlap. */
const overlaps = (a: Point, b: Point): boolean =>
  a.x < b.x + W && b.x < a.x + W && a.y < b.y + H && b.y < a.y + H;

describe("placing blocks that have no position yet", () => {
  test("a free spot is kept as it is", () => {
    expect(freeSpot({ x: 500, y: 0 }, [{ x: 0, y: 0 }])).toEqual({ x: 500, y: 0 });
  });

  test("a taken spot moves to the nearest free one, below first", () => {
    const p = freeSpot({ x: 0, y: 0 }, [{ x: 0, y: 0 }]);
    expect(overlaps(p, { x: 0, y: 0 })).toBe(false);
    expect(p.x).toBe(0);
    expect(p.y).toBeGreaterThan(0);
  });

  test("without any position the automatic layout is used as it is", () => {
    const auto = new Map([
      ["A", { x: 0, y: 0 }],
      ["B", { x: 250, y: 0 }],
    ]);
    const out = placeBlocks(
      [
        { name: "A", inputs: [] },
        { name: "B", inputs: ["A"] },
      ],
      auto,
    );
    expect(out).toEqual(auto);
  });

  test("a block added to a drawn pipeline goes beside its input, on no other node", () => {
    // A chain drawn left to right; Extra reads from Emg, whose right neighbour is Amplification.
    const drawn = ["Timer", "Emg", "Amplification", "Rectification"].map((name, i) => ({
      name,
      inputs: i > 0 ? [["Timer", "Emg", "Amplification"][i - 1]!] : [],
      at: { x: i * (W + DEFAULT_LAYOUT.gapX), y: 0 },
    }));
    // Where the automatic layout of the new graph would put it: on Amplification's spot.
    const auto = new Map([["Extra", { x: W + DEFAULT_LAYOUT.gapX, y: 0 }]]);
    const out = placeBlocks([...drawn, { name: "Extra", inputs: ["Emg"] }], auto);
    const extra = out.get("Extra")!;
    for (const b of drawn) {
      expect(out.get(b.name)).toEqual(b.at);
      expect(overlaps(extra, b.at), `Extra on ${b.name}`).toBe(false);
    }
    // Right of Emg's column (one layer on), just below the chain.
    expect(extra.x).toBe(2 * (W + DEFAULT_LAYOUT.gapX));
    expect(extra.y).toBeGreaterThan(0);
    expect(extra.y).toBeLessThan(2 * H);
  });

  test("several new blocks do not land on each other either", () => {
    const out = placeBlocks(
      [
        { name: "A", inputs: [], at: { x: 0, y: 0 } },
        { name: "B", inputs: ["A"] },
        { name: "C", inputs: ["A"] },
        { name: "D", inputs: ["A"] },
      ],
      new Map(),
    );
    const ps = [...out.values()];
    for (let i = 0; i < ps.length; i++)
      for (let j = i + 1; j < ps.length; j++) expect(overlaps(ps[i]!, ps[j]!)).toBe(false);
  });
});

describe("a pipeline's positions (the BlockTable's)", () => {
  test("a block without a Layout key among blocks with one lands on none of them", () => {
    // A and B saved side by side; C (reading A, added later in the text) has no Layout: the
    // automatic layout alone would put it in B's layer, at B's place.
    const blocks = [
      { name: "A", inputs: [], layout: { x: 0, y: 0 } },
      { name: "B", inputs: ["A"], layout: { x: W + DEFAULT_LAYOUT.gapX, y: 0 } },
      { name: "C", inputs: ["A"] },
    ];
    const out = pipelinePositions(blocks);
    expect(out.get("A")).toEqual({ x: 0, y: 0 });
    expect(out.get("B")).toEqual({ x: W + DEFAULT_LAYOUT.gapX, y: 0 });
    expect(overlaps(out.get("C")!, out.get("A")!)).toBe(false);
    expect(overlaps(out.get("C")!, out.get("B")!)).toBe(false);
  });

  test("without Layout keys it is the automatic layout", () => {
    const out = pipelinePositions([
      { name: "A", inputs: [] },
      { name: "B", inputs: ["A"] },
    ]);
    expect(out.get("B")!.x).toBeGreaterThan(out.get("A")!.x);
    expect(overlaps(out.get("A")!, out.get("B")!)).toBe(false);
  });
});
