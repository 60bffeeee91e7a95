import { describe, expect, test } from "vitest";
import { z } from "zod";
import { defineBlock, type InputInfo, type PortMeta } from "../block";
import { createCatalog } from "../catalog";
import { vectorShape } from "../frame";
import { TEST_BLOCKS } from "../test-blocks";
import { runVirtualPipeline } from "../testing";

/** What each Probe saw of its inputs, by block name. */
const seen = new Map<string, readonly InputInfo[]>();

/** A source of `N` values whose port says what they are (or says nothing). */
const Named = defineBlock({
  type: "Named",
  category: "Testing",
  summary: "named",
  help: "named",
  params: z.strictObject({
    N: z.number().int().default(2).describe("values"),
    Labels: z.array(z.string()).optional().describe("labels"),
    Grid: z.boolean().default(false).describe("declare a 1 × N grid, reversed"),
  }),
  inputs: { min: 1, max: 1 },
  create(ctx, p) {
    const meta: PortMeta = {
      ...(p.Labels ? { labels: p.Labels, unit: "mV" } : {}),
      ...(p.Grid
        ? {
            grid: { rows: 1, cols: p.N, cells: Array.from({ length: p.N }, (_, i) => p.N - 1 - i) },
          }
        : {}),
    };
    ctx.output(vectorShape(p.N), undefined, meta);
    return {};
  },
});

/** Records its inputs' InputInfo; outputs `N` values without meta of its own. */
const Probe = defineBlock({
  type: "Probe",
  category: "Testing",
  summary: "probe",
  help: "probe",
  params: z.strictObject({ N: z.number().int().default(2).describe("values") }),
  inputs: { min: 1, max: 2 },
  create(ctx, p) {
    seen.set(ctx.name, ctx.inputs);
    ctx.output(vectorShape(p.N));
    return {};
  },
});

const catalog = createCatalog([...TEST_BLOCKS, Named, Probe]);
const run = (yaml: string) => runVirtualPipeline(yaml, { catalog, duration: 0.01 });

describe("port meta (channel names, unit, electrode grid)", () => {
  test("declared labels reach consumers; same-shape outputs inherit them, other shapes do not", async () => {
    await run(`
T: { Type: Tick, DesiredRate: 100 }
Src: { Type: Named, Inputs: [T], Params: { N: 2, Labels: [left, right], Grid: true } }
Same: { Type: Probe, Inputs: [T, Src], Params: { N: 2 } }
Next: { Type: Probe, Inputs: [Same] }
Other: { Type: Probe, Inputs: [Src], Params: { N: 3 } }
Last: { Type: Probe, Inputs: [Other] }
`);
    const meta = {
      labels: ["left", "right"],
      unit: "mV",
      grid: { rows: 1, cols: 2, cells: [1, 0] },
    };
    expect(seen.get("Same")![1]!.meta).toEqual(meta);
    // The timer input (first) has no meta; Same's output inherits from its first value input.
    expect(seen.get("Same")![0]!.meta).toBeUndefined();
    expect(seen.get("Next")![0]!.meta).toEqual(meta);
    // A different shape means other values: nothing is inherited.
    expect(seen.get("Other")![0]!.meta).toEqual(meta);
    expect(seen.get("Last")![0]!.meta).toBeUndefined();
  });

  test("labels or a grid that do not fit the shape are a load error naming the port", async () => {
    await expect(
      run(`
T: { Type: Tick, DesiredRate: 100 }
Src: { Type: Named, Inputs: [T], Params: { N: 3, Labels: [a, b] } }
`),
    ).rejects.toThrow(/block 'Src' \(Named\): output 'out': 2 channel labels for 3 values/);
  });
});
