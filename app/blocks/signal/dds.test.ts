import { readFileSync } from "node:fs";
import { join } from "node:path";
import { describe, expect, test } from "vitest";
import { createCatalog, Frame, loadPipeline, matrixShape, vectorShape } from "../../engine";
import { BlockHarness } from "../../engine/testing";
import { DoubleDifferential } from "./dds";

interface Case {
  rows: number;
  cols: number;
  direction: "rows" | "columns";
  layout: "row-major" | "column-major";
  x: number[][];
  y: number[][];
}
const fx = JSON.parse(readFileSync(join(__dirname, "fixtures", "dds.json"), "utf8")) as {
  cases: Case[];
};

describe("ddS (spatial double differential)", () => {
  test.each(fx.cases)(
    "$rows × $cols along $direction, $layout: bit for bit as NumPy",
    async (c) => {
      const h = await BlockHarness.create(
        DoubleDifferential,
        { Rows: c.rows, Columns: c.cols, Direction: c.direction, Layout: c.layout },
        { inputs: [{ shape: vectorShape(c.rows * c.cols), rate: 2000 }] },
      );
      const t = c.x.map((_, i) => i / 2000);
      h.push(Frame.from(vectorShape(c.rows * c.cols), t, c.x));
      expect(h.output().v).toEqual(c.y);
      expect(h.output().t).toEqual(t);
    },
  );

  test("a window [n, channels] is filtered row by row", async () => {
    const c = fx.cases[0]!;
    const w = c.rows * c.cols;
    const h = await BlockHarness.create(
      DoubleDifferential,
      { Rows: c.rows, Columns: c.cols },
      { inputs: [{ shape: matrixShape(5, w) }] },
    );
    expect(h.ports[0]!.shape).toEqual(matrixShape(5, c.y[0]!.length));
    h.push(Frame.from(matrixShape(5, w), [0], [c.x.flat()]));
    expect(h.output().v).toEqual([c.y.flat()]);
  });

  test("the grid must match the input; MOSAIC's ['8;4'] loads", async () => {
    await expect(
      BlockHarness.create(
        DoubleDifferential,
        { Rows: 8, Columns: 4 },
        { inputs: [{ shape: vectorShape(30) }] },
      ),
    ).rejects.toThrow(/30 channels, but a 8 × 4 grid has 32/);
    await expect(
      BlockHarness.create(
        DoubleDifferential,
        { Rows: 2, Columns: 16 },
        { inputs: [{ shape: vectorShape(32) }] },
      ),
    ).rejects.toThrow(/needs 3 electrodes along Rows/);
    const r = loadPipeline(
      "D: { Type: ddS, Inputs: [D], Params: [ '8;4' ] }\n",
      "p.yaml",
      createCatalog([DoubleDifferential]),
    );
    expect(r.spec!.blocks[0]!.params).toEqual({
      Rows: 8,
      Columns: 4,
      Direction: "rows",
      Layout: "row-major",
    });
  });
});
