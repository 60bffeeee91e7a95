import { describe, expect, test } from "vitest";
import { catalog } from "../catalog";
import { vectorShape } from "../../engine";
import { BlockHarness, runVirtualPipeline } from "../../engine/testing";
import { convertLegacy, loadBlock, vectors } from "../../../tests/support/blocks";
import { Splitter } from "./splitter";

const eight = { shape: vectorShape(8), rate: 100 };
const row = [10, 11, 12, 13, 14, 15, 16, 17];

describe("Splitter", () => {
  test("Parts: named ports carry the listed indices in order", async () => {
    const h = await BlockHarness.create(
      Splitter,
      { Parts: { flexors: [0, 1, 2], extensors: [6, 5, 4, 4] } },
      { inputs: [eight] },
    );
    h.start();
    h.push(vectors([1, 2], [row, row.map((x) => -x)]));
    expect(h.output("flexors")).toEqual({
      t: [1, 2],
      v: [
        [10, 11, 12],
        [-10, -11, -12],
      ],
      frames: [2],
    });
    expect(h.output("extensors").v).toEqual([
      [16, 15, 14, 14],
      [-16, -15, -14, -14],
    ]);
    expect(h.ports.map((p) => [p.name, p.shape.cols])).toEqual([
      ["flexors", 3],
      ["extensors", 4],
    ]);
  });

  test("Sizes: consecutive parts on ports 0, 1, …", async () => {
    const h = await BlockHarness.create(Splitter, { Sizes: [3, 5] }, { inputs: [eight] });
    h.start();
    h.push(vectors([1], [row]));
    expect(h.output("0").v).toEqual([[10, 11, 12]]);
    expect(h.output("1").v).toEqual([[13, 14, 15, 16, 17]]);
  });

  test("downstream blocks subscribe to a port as Split.name", async () => {
    const run = await runVirtualPipeline(
      `
Timer: { Type: ScheduledTimer, DesiredRate: 10 }
Sin: { Type: SinGenerator, Inputs: [Timer], Params: { Components: 4, Frequency: 1 } }
Split: { Type: Splitter, Inputs: [Sin], Params: { Parts: { first: [0], rest: [1, 2, 3] } } }
Back: { Type: Projector, Inputs: [Split.rest], Params: { Indices: [2, 1, 0] } }
`,
      { catalog, duration: 0.5 },
    );
    const sin = run.outputs.get("Sin")!;
    const back = run.outputs.get("Back")!;
    expect(back.t).toHaveLength(6);
    expect(back.t).toEqual(sin.t);
    expect(back.v).toEqual(sin.v.map((v) => [v[3], v[2], v[1]]));
  });

  test("errors: index out of range, sizes that do not add up, both or neither form", async () => {
    await expect(
      BlockHarness.create(Splitter, { Parts: { a: [0, 9] } }, { inputs: [eight] }),
    ).rejects.toThrow(
      "index 9 is out of range for input 'in0' (part 'a') with 8 channels (valid: 0–7)",
    );
    await expect(
      BlockHarness.create(Splitter, { Sizes: [4, 5] }, { inputs: [eight] }),
    ).rejects.toThrow(
      "Sizes [4, 5] add up to 9, but input 'in0' has 8 channels; the sizes must add up to the input width",
    );
    const both = loadBlock(
      "T: { Type: ScheduledTimer, DesiredRate: 10 }\nS: { Type: SinGenerator, Inputs: [T] }\n" +
        "X: { Type: Splitter, Inputs: [S], Params: { Sizes: [1], Parts: { a: [0] } } }\n",
      "X",
    );
    expect(both.errors[0]!.message).toContain("give exactly one of Parts");
    const badName = loadBlock(
      "T: { Type: ScheduledTimer, DesiredRate: 10 }\nS: { Type: SinGenerator, Inputs: [T] }\n" +
        "X: { Type: Splitter, Inputs: [S], Params: { Parts: { a.b: [0] } } }\n",
      "X",
    );
    expect(badName.errors).toHaveLength(1);
  });

  test("legacy [a;b;c] = Sizes", () => {
    expect(
      convertLegacy(
        "T: { Type: ScheduledTimer, DesiredRate: 10 }\n" +
          "S: { Type: SinGenerator, Inputs: [T], Params: { Components: 6 } }\n" +
          "X: { Type: Splitter, Inputs: [S], Params: ['2;4'] }\n" +
          "Y: { Type: Projector, Inputs: [X.1], Params: { Indices: [0] } }\n",
        "X",
      ),
    ).toEqual({ Sizes: [2, 4] });
  });
});
