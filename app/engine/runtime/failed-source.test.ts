/**
 * A block that cannot be created (its file is missing) is the one error reported: the blocks it
 * feeds cannot know their input's shape either, and their errors would only repeat it while
 * blaming a feedback cycle (issue 17, defect 5).
 */
import { describe, expect, test } from "vitest";
import { z } from "zod";
import { defineBlock } from "../block";
import { createCatalog } from "../catalog";
import { BlockConfigError } from "../diagnostics";
import { vectorShape } from "../frame";
import { TEST_BLOCKS } from "../test-blocks";
import { noResources } from "../testing";
import { validatePipeline } from "../validate";

/** Reads its `File` when created (as a FilePlayer does): fails when the file is not there. */
const Reader = defineBlock({
  type: "Reader",
  category: "Testing",
  summary: "reads a file",
  help: "reads a file",
  params: z.strictObject({ File: z.string().describe("a file") }),
  inputs: { min: 0, max: 0 },
  async create(ctx, p) {
    try {
      await ctx.resources.readText(p.File);
    } catch (e) {
      throw new BlockConfigError(`cannot read '${p.File}': ${(e as Error).message}`, "File");
    }
    ctx.output(vectorShape(1));
    return {};
  },
});

/** Needs its input's shape when created (as most signal blocks do). */
const Shaped = defineBlock({
  type: "Shaped",
  category: "Testing",
  summary: "needs a shape",
  help: "needs a shape",
  params: z.strictObject({ Bad: z.boolean().default(false).describe("fails on its own") }),
  inputs: { min: 1, max: 1 },
  create(ctx, p) {
    if (p.Bad) throw new BlockConfigError("this block is misconfigured on its own", "Bad");
    const shape = ctx.inputs[0]!.shape;
    if (shape === null) {
      throw new BlockConfigError(
        "the shape of its input is unknown (it is created later inside a feedback cycle)",
      );
    }
    ctx.output(shape);
    return {};
  },
});

const catalog = createCatalog([...TEST_BLOCKS, Reader, Shaped]);

const errors = async (yaml: string): Promise<string[]> =>
  (await validatePipeline(yaml, "test.yaml", catalog, { resources: noResources }))
    .filter((d) => d.severity === "error")
    .map((d) => `${d.block ?? ""}/${d.param ?? ""}: ${d.message}`);

describe("a block that cannot be created", () => {
  test("is the one error: the chain it feeds is not blamed on a feedback cycle", async () => {
    const found = await errors(`
Recording: { Type: Reader, Params: { File: ../data/missing.csv } }
Rectified: { Type: Shaped, Inputs: [Recording] }
Envelope: { Type: Shaped, Inputs: [Rectified] }
Sampled: { Type: Shaped, Inputs: [Envelope] }
`);
    expect(found).toHaveLength(1);
    expect(found[0]).toMatch(
      /^Recording\/File: block 'Recording' \(Reader\): cannot read '\.\.\/data\/missing\.csv'/,
    );
    expect(found.join("\n")).not.toMatch(/feedback cycle/);
  });

  test("blocks that do not depend on it still report their own errors", async () => {
    const found = await errors(`
Recording: { Type: Reader, Params: { File: missing.csv } }
After: { Type: Shaped, Inputs: [Recording] }
T: { Type: Tick, DesiredRate: 10 }
C: { Type: Counter, Inputs: [T] }
Other: { Type: Shaped, Inputs: [C], Params: { Bad: true } }
`);
    expect(found.map((f) => f.split(":")[0])).toEqual(["Recording/File", "Other/Bad"]);
  });

  test("a real feedback cycle whose source is created later is still reported, once", async () => {
    const found = await errors(`
A: { Type: Shaped, Inputs: [B] }
B: { Type: Shaped, Inputs: [A] }
`);
    expect(found).toHaveLength(1);
    expect(found[0]).toMatch(/^A\/: .*feedback cycle/);
  });
});
