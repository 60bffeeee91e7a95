import { describe, expect, test } from "vitest";
import { z } from "zod";
import { defineBlock } from "./block";
import { loadPipeline } from "./pipeline/loader";
import { TestGain, testCatalog } from "./test-blocks";
import { runVirtualPipeline } from "./testing";
import {
  blockDefinitions,
  blockModuleRefs,
  joinModulePath,
  pipelineCatalog,
  userBlockOrigin,
  type ModuleLoader,
} from "./user-blocks";

/** Modules held in memory, by absolute path: what a platform's loader would give back. */
function memoryModules(modules: Record<string, Record<string, unknown>>): ModuleLoader {
  return (path) =>
    Promise.resolve(
      modules[path]
        ? { ok: true, exports: modules[path], inputs: [path] }
        : { ok: false, message: "no such file", inputs: [path] },
    );
}

const Double = defineBlock({
  type: "Double",
  category: "Testing",
  summary: "twice the input",
  help: "y = 2x",
  params: z.strictObject({}),
  inputs: { min: 1, max: 1 },
  create: (ctx) => TestGain.create(ctx, { Gain: 2 }),
});

const Garbage = defineBlock({
  ...Double,
  type: "Garbage",
  create: () => 42 as never,
});

const PIPE =
  "Pipeline:\n  Blocks: [blocks/double.ts]\n" +
  "T: { Type: Tick, DesiredRate: 10 }\n" +
  "C: { Type: Counter, Inputs: [T] }\n" +
  "D: { Type: Double, Inputs: [C] }\n";

describe("Pipeline: { Blocks }", () => {
  test("the loader accepts a list of module files and refuses anything else where it is", () => {
    expect(loadPipeline(PIPE.replace(/D:.*\n/, ""), "p.yaml", testCatalog).ok).toBe(true);
    const bad = loadPipeline(
      "Pipeline: { Blocks: [notes.txt, 3] }\nT: { Type: Tick, DesiredRate: 10 }\n",
      "p.yaml",
      testCatalog,
    );
    expect(bad.diagnostics.map((d) => [d.line, d.col, d.message])).toEqual([
      [1, 22, "Pipeline: Blocks entry 'notes.txt' is not a module file"],
      [1, 33, "Pipeline: Blocks entry '3' is not a module file"],
    ]);
    const notList = loadPipeline("Pipeline: { Blocks: x.ts }\n", "p.yaml", testCatalog);
    expect(notList.diagnostics[0]).toMatchObject({ line: 1, col: 21, code: "bad-blocks" });
  });

  test("entries are read with their positions; paths join the pipeline's folder", () => {
    expect(blockModuleRefs(PIPE, "/a/p.yaml")).toEqual([
      { path: "blocks/double.ts", pos: { line: 2, col: 12 } },
    ]);
    expect(joinModulePath("/a/b", "blocks/x.ts")).toBe("/a/b/blocks/x.ts");
    expect(joinModulePath("/a/b", "../x.ts")).toBe("/a/x.ts");
    expect(joinModulePath("/a/b", "/abs/x.ts")).toBe("/abs/x.ts");
    expect(joinModulePath(".", "../x.ts")).toBe("../x.ts");
    expect(joinModulePath("/", "../x.ts")).toBe("/x.ts");
  });
});

describe("pipelineCatalog", () => {
  test("a module's blocks run in the pipeline, and know where they came from", async () => {
    const load = memoryModules({ "/a/blocks/double.ts": { default: Double } });
    const own = await pipelineCatalog(PIPE, "/a/p.yaml", testCatalog, load);
    expect(own.diagnostics).toEqual([]);
    const def = own.catalog.get("Double")!;
    expect(userBlockOrigin(def)).toBe("blocks/double.ts");
    expect(def.help).toContain("blocks/double.ts");
    const run = await runVirtualPipeline(PIPE, { catalog: own.catalog, duration: 0.35 });
    expect(run.outputs.get("D")!.v).toEqual([[2], [4], [6], [8]]);
  });

  test("each problem is an error at the module's entry, naming the file and the reason", async () => {
    const text =
      "Pipeline: { Blocks: [a.ts, b.js, c.ts, d.mjs] }\nT: { Type: Tick, DesiredRate: 10 }\n";
    const load = memoryModules({
      "/p/a.ts": { default: { foo: 1 } },
      "/p/c.ts": { default: [TestGain] },
      "/p/d.mjs": { helper: 3 },
    });
    const own = await pipelineCatalog(text, "/p/x.yaml", testCatalog, load);
    expect(own.diagnostics.map((d) => `${d.line}:${d.col} ${d.message}`)).toEqual([
      "1:22 user blocks in a.ts: its default export is not a block definition (an object with keys foo; expected defineBlock({ type, create, ... }))",
      "1:28 cannot load user blocks from b.js: no such file",
      "1:40 user blocks in d.mjs: it exports no block definition (export default defineBlock({...}))",
      "1:34 user block type 'Gain' in c.ts is a built-in block type: pick another name",
    ]);
  });

  test("without a module loader (the browser build) such a pipeline is refused, saying why", async () => {
    const own = await pipelineCatalog(PIPE, "/a/p.yaml", testCatalog, undefined);
    expect(own.diagnostics[0]!.message).toMatch(/this engine cannot load block modules/);
  });

  test("create() returning garbage is an error at the block, not a crash in the runtime", async () => {
    const text = PIPE.replace("Type: Double", "Type: Garbage");
    const load = memoryModules({ "/a/blocks/double.ts": { Garbage } });
    const own = await pipelineCatalog(text, "/a/p.yaml", testCatalog, load);
    await expect(runVirtualPipeline(text, { catalog: own.catalog, duration: 0.1 })).rejects.toThrow(
      "user block 'Garbage' (blocks/double.ts): create() returned number instead of an object",
    );
  });

  test("a module's default export may list several blocks; named exports count too", () => {
    const found = blockDefinitions({ default: [Double, Garbage], Double, contract: {} });
    expect(found.defs.map((d) => d.type)).toEqual(["Double", "Garbage"]);
    expect(found.problems).toEqual([]);
  });
});
