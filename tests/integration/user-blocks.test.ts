/**
 * Blocks written by users (issue 18), end to end through the real CLI, in a folder outside the
 * repository made only from docs/writing-blocks.md: its TypeScript block, its pipeline and its
 * tsconfig are taken from the guide's code, type-checked against the SDK, put through
 * `mosaic test-block`, validated and run headless (the output checked against the block's
 * formula). Broken modules and blocks — a syntax error, a `process` that throws, a `process`
 * that never returns on its own worker — each give a message naming the file or block, and the
 * rest of the pipeline keeps running.
 */
import { execFileSync, type ChildProcess } from "node:child_process";
import { existsSync, mkdirSync, readFileSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import WebSocket from "ws";
import type { EngineMessage } from "../../app/engine/protocol";
import { decodeWire, encodeWire } from "../../app/engine/protocol-wire";
import { jsonLines, requireBuild, ROOT, runCli, startCli, tempDir, until } from "./helpers";

beforeAll(requireBuild);

/** The guide's code blocks, by language, in order. */
function guideCode(): { lang: string; text: string }[] {
  const md = readFileSync(join(ROOT, "docs/writing-blocks.md"), "utf8");
  return [...md.matchAll(/```(\w+)\n([\s\S]*?)```/g)].map((m) => ({ lang: m[1]!, text: m[2]! }));
}

/** A folder outside the repository with the guide's block, pipeline and tsconfig. */
function projectFromGuide(): string {
  const code = guideCode();
  const block = code.find((c) => c.lang === "ts" && c.text.includes("defineBlock({"))!;
  const pipeline = code.find((c) => c.lang === "yaml" && c.text.includes("Blocks:"))!;
  const tsconfig = code.find((c) => c.lang === "json" && c.text.includes('"mosaic/sdk"'))!;
  const dir = tempDir("mosaic-user-blocks-");
  expect(dir.startsWith(ROOT)).toBe(false);
  mkdirSync(join(dir, "blocks"));
  writeFileSync(join(dir, "blocks/smoother.ts"), block.text);
  writeFileSync(join(dir, "pipeline.yaml"), pipeline.text);
  const root = ROOT.replace(/\/$/, "");
  writeFileSync(join(dir, "tsconfig.json"), tsconfig.text.replaceAll("/path/to/mosaic", root));
  return dir;
}

/** Rows of a `Path` log: [t, v1, …]. */
function readLog(file: string): number[][] {
  return readFileSync(file, "utf8")
    .trim()
    .split("\n")
    .map((l) => l.split(",").map(Number));
}

describe("a TypeScript block made from docs/writing-blocks.md", () => {
  let dir: string;
  beforeAll(() => {
    dir = projectFromGuide();
  });

  test("type-checks against the SDK with the guide's tsconfig", () => {
    // Throws (with the compiler's messages) when the SDK's types reject the guide's block.
    execFileSync(join(ROOT, "node_modules/.bin/tsc"), ["-p", dir], { encoding: "utf8" });
    // And the types mean something: a param the schema does not have is a compile error.
    const src = readFileSync(join(dir, "blocks/smoother.ts"), "utf8");
    writeFileSync(join(dir, "blocks/wrong.ts"), src.replace("p.Alpha", "p.Beta"));
    let out = "";
    try {
      execFileSync(join(ROOT, "node_modules/.bin/tsc"), ["-p", dir], { encoding: "utf8" });
    } catch (e) {
      out = String((e as { stdout?: string }).stdout);
    } finally {
      writeFileSync(join(dir, "blocks/wrong.ts"), "export {};\n");
    }
    expect(out).toMatch(/wrong\.ts.*Property 'Beta' does not exist/);
  }, 120_000);

  test("passes mosaic test-block: every check of the built-in blocks' contract", () => {
    const r = runCli(["test-block", "blocks/smoother.ts"], { cwd: dir });
    expect(r.stderr).toBe("");
    expect(r.code).toBe(0);
    const checks = r.stdout.split("\n").filter((l) => /^\s+(PASS|FAIL) /.test(l));
    expect(checks.map((l) => l.trim().split(":")[0])).toEqual([
      "PASS docs",
      "PASS defaults validate",
      "PASS frame splitting",
      "PASS reset repeats",
      "PASS dispose twice",
      "PASS garbage params",
    ]);
  }, 60_000);

  test("validates, and runs headless with the output the formula gives", () => {
    expect(runCli(["validate", "pipeline.yaml"], { cwd: dir }).code).toBe(0);
    // mosaic format knows the file (its own blocks included) and leaves it as it is.
    const f = runCli(["format", "pipeline.yaml", "--check"], { cwd: dir });
    expect([f.code, f.stdout.trim()]).toEqual([0, "pipeline.yaml: unchanged"]);
    const r = runCli(["run", "pipeline.yaml", "--clock", "virtual", "--duration", "2", "--json"], {
      cwd: dir,
    });
    expect(r.stderr).toBe("");
    expect(r.code).toBe(0);
    const summary = jsonLines(r.stdout).find((l) => l.type === "summary") as {
      blocks: { name: string; type: string; errors?: number }[];
    };
    expect(summary.blocks.find((b) => b.name === "Smooth")?.type).toBe("Smoother");
    // The guide's pipeline: a 2 Hz sine at 100 Hz, smoothed with Alpha 0.2 from y = 0.
    const rows = readLog(join(dir, "smooth.csv"));
    expect(rows.length).toBe(201);
    let y = 0;
    rows.forEach(([t, v], k) => {
      expect(t).toBeCloseTo(k / 100, 6);
      y += 0.2 * (Math.sin(2 * Math.PI * 2 * (k / 100)) - y);
      expect(Math.abs(v! - y)).toBeLessThan(1e-12);
    });
  }, 60_000);

  test("the guide's gen-docs --pipeline writes the pipeline's reference and JSON Schema", () => {
    execFileSync(
      process.execPath,
      [join(ROOT, "dist/tools/gen-docs.mjs"), "--pipeline", "pipeline.yaml"],
      {
        cwd: dir,
        encoding: "utf8",
      },
    );
    const md = readFileSync(join(dir, "blocks.md"), "utf8");
    expect(md).toMatch(/### Smoother\n\n\*\*Exponential smoothing of every channel/);
    expect(md).toContain("(User block from blocks/smoother.ts.)");
    const schema = JSON.parse(readFileSync(join(dir, "pipeline.schema.json"), "utf8")) as {
      definitions: Record<
        string,
        { properties: Record<string, { enum?: string[]; maximum?: number }> }
      >;
    };
    expect(schema.definitions.Block!.properties.Type!.enum).toContain("Smoother");
    expect(schema.definitions.Block!.properties.Type!.enum).toContain("Filter");
    expect(schema.definitions["Smoother.Params"]!.properties.Alpha!.maximum).toBe(1);
  }, 60_000);
});

const BROKEN = `import { defineBlock, z } from "mosaic/sdk";

export const Thrower = defineBlock({
  type: "Thrower",
  category: "Testing",
  summary: "Throws in process.",
  help: "Deliberately broken: every call of process throws.",
  params: z.strictObject({}),
  inputs: { min: 1, max: 1 },
  create(ctx) {
    ctx.output(ctx.inputs[0]!.shape!);
    return {
      process() {
        throw new Error("thrower is broken on purpose");
      },
    };
  },
});

export const Looper = defineBlock({
  type: "Looper",
  category: "Testing",
  summary: "Never returns from process.",
  help: "Deliberately broken: process loops forever.",
  params: z.strictObject({}),
  inputs: { min: 1, max: 1 },
  outputs: [],
  create() {
    return {
      process() {
        for (;;) {
          // forever
        }
      },
    };
  },
});
`;

describe("broken user blocks", () => {
  let dir: string;
  beforeAll(() => {
    dir = projectFromGuide();
    writeFileSync(join(dir, "blocks/broken.ts"), BROKEN);
  });

  test("a syntax error names the module, its line and column, at the Blocks: entry", () => {
    writeFileSync(
      join(dir, "blocks/typo.ts"),
      'import { defineBlock } from "mosaic/sdk";\nexport default defineBlock({\n  type: "Typo" oops,\n});\n',
    );
    writeFileSync(
      join(dir, "typo.yaml"),
      "Pipeline:\n  Blocks:\n    - blocks/smoother.ts\n    - blocks/typo.ts\n" +
        "Clock: { Type: ScheduledTimer, DesiredRate: 100 }\n",
    );
    for (const args of [["validate"], ["run", "--duration", "1"]]) {
      const r = runCli([...args, "typo.yaml"], { cwd: dir });
      expect(r.code).toBe(2);
      expect(r.stderr).toMatch(
        /typo\.yaml:4:7: error: cannot load user blocks from blocks\/typo\.ts:3:16: Expected "}" but found "oops"/,
      );
    }
  }, 60_000);

  test("a module whose top level throws names the file and line", () => {
    writeFileSync(
      join(dir, "blocks/boom.ts"),
      'const ready: boolean = false;\n\nif (!ready) {\n  throw new Error("not configured");\n}\nexport {};\n',
    );
    writeFileSync(
      join(dir, "boom.yaml"),
      "Pipeline: { Blocks: [blocks/boom.ts] }\nClock: { Type: ScheduledTimer, DesiredRate: 100 }\n",
    );
    const r = runCli(["validate", "boom.yaml"], { cwd: dir });
    expect(r.code).toBe(2);
    expect(r.stderr).toContain(
      "boom.yaml:1:22: error: cannot load user blocks from blocks/boom.ts:4:9: its top level threw: not configured",
    );
  }, 60_000);

  test("a module that is not blocks, a missing one and a clash with a built-in are named", () => {
    writeFileSync(join(dir, "blocks/notblock.js"), "export default { foo: 1 };\n");
    writeFileSync(
      join(dir, "blocks/clash.ts"),
      readFileSync(join(dir, "blocks/smoother.ts"), "utf8").replace('"Smoother"', '"Filter"'),
    );
    writeFileSync(
      join(dir, "odd.yaml"),
      "Pipeline: { Blocks: [blocks/notblock.js, blocks/gone.ts, blocks/clash.ts] }\n" +
        "Clock: { Type: ScheduledTimer, DesiredRate: 100 }\n",
    );
    const r = runCli(["validate", "odd.yaml"], { cwd: dir });
    expect(r.code).toBe(2);
    const lines = r.stderr.split("\n").filter((l) => l.includes("error:"));
    expect(lines).toEqual([
      "odd.yaml:1:22: error: user blocks in blocks/notblock.js: its default export is not a block definition (an object with keys foo; expected defineBlock({ type, create, ... }))",
      "odd.yaml:1:42: error: cannot load user blocks from blocks/gone.ts: no such file",
      "odd.yaml:1:58: error: user block type 'Filter' in blocks/clash.ts is a built-in block type: pick another name",
    ]);
  }, 60_000);

  test("mosaic test-block fails a block that never returns in its check and goes on", () => {
    const r = runCli(["test-block", "blocks/broken.ts", "--timeout", "8"], {
      cwd: dir,
      timeoutMs: 90_000,
    });
    expect(r.code).toBe(1);
    const lines = r.stdout.split("\n");
    const at = (block: string) => lines.indexOf(`blocks/broken.ts: ${block}`);
    expect(at("Looper")).toBeGreaterThanOrEqual(0);
    expect(lines.slice(at("Looper") + 1, at("Looper") + 5)).toEqual([
      "  PASS docs: summary, help and 0 described params",
      "  PASS defaults validate: params {}; outputs []",
      "  FAIL frame splitting: did not finish within 8 s — a block that never returns (an endless loop in process, create or a timer?)",
      "  Looper: stopped in frame splitting",
    ]);
    // The module's other block is still tested, after the stuck one.
    expect(at("Thrower")).toBeGreaterThan(at("Looper"));
    expect(lines).toContain("  FAIL frame splitting: Error: thrower is broken on purpose");
  }, 120_000);

  test("a throwing process and an endless loop on its own worker: named, and the rest runs", () => {
    writeFileSync(
      join(dir, "broken.yaml"),
      "Pipeline:\n  Blocks: [blocks/smoother.ts, blocks/broken.ts]\n" +
        "Clock: { Type: ScheduledTimer, DesiredRate: 100 }\n" +
        "Sine: { Type: SinGenerator, Inputs: [Clock] }\n" +
        "Smooth: { Type: Smoother, Inputs: [Sine], Path: broken-smooth.csv }\n" +
        "Throw: { Type: Thrower, Inputs: [Sine] }\n" +
        "Loop: { Type: Looper, Inputs: [Sine], Worker: stuck }\n",
    );
    const r = runCli(["run", "broken.yaml", "--duration", "5", "--json"], {
      cwd: dir,
      timeoutMs: 60_000,
    });
    const lines = jsonLines(r.stdout);
    const events = lines.filter((l) => l.type === "event") as {
      level: string;
      block: string;
      message: string;
    }[];
    // The block, and the file and line that threw (the module's source map).
    expect(events).toContainEqual(
      expect.objectContaining({
        level: "error",
        block: "Throw",
        message: "thrower is broken on purpose (at blocks/broken.ts:14:15)",
      }),
    );
    const stuck = events.find((e) => e.block === "Loop");
    expect(stuck?.message).toMatch(
      /^engine worker 'stuck' has not answered for \d+\.\d s: its blocks 'Loop' \(Looper\) are stuck/,
    );
    // Exit 1 (a runtime failure: the thrower's errors), after the full duration.
    expect(r.code).toBe(1);
    const summary = lines.find((l) => l.type === "summary") as {
      reason: string;
      blocks: { name: string; events: number; errors: number }[];
    };
    expect(summary.reason).toBe("duration");
    const byName = new Map(summary.blocks.map((b) => [b.name, b]));
    expect(byName.get("Throw")!.errors).toBeGreaterThan(100);
    // The smoother on the main worker went on for the whole run (100 Hz for 5 s).
    expect(byName.get("Smooth")!.events).toBeGreaterThan(400);
    expect(readLog(join(dir, "broken-smooth.csv")).length).toBeGreaterThan(400);
  }, 90_000);
});

describe("user blocks under mosaic serve: a page's pipeline runs code only from its folders", () => {
  let dir: string;
  let outside: string;
  let cli: ChildProcess;
  let ws: WebSocket;
  const got: EngineMessage[] = [];

  beforeAll(async () => {
    dir = projectFromGuide();
    outside = tempDir("mosaic-user-blocks-outside-");
    // Top-level code that would leave a mark if it ever ran.
    writeFileSync(
      join(outside, "evil.mjs"),
      `import { writeFileSync } from "node:fs";\nwriteFileSync(${JSON.stringify(join(outside, "ran"))}, "x");\nexport default {};\n`,
    );
    cli = startCli(["serve", join(dir, "pipeline.yaml"), "--port", "0", "--no-start"]);
    let out = "";
    const url = await new Promise<URL>((resolve, reject) => {
      const t = setTimeout(() => reject(new Error(`no URL printed: ${out}`)), 30_000);
      cli.stderr!.on("data", (d: Buffer) => (out += d.toString()));
      cli.stdout!.on("data", (d: Buffer) => {
        out += d.toString();
        const m = /MOSAIC is at (\S+)/.exec(out);
        if (m) {
          clearTimeout(t);
          resolve(new URL(m[1]!));
        }
      });
    });
    const target = new URL("/ws", url);
    target.protocol = "ws:";
    target.searchParams.set("token", url.searchParams.get("token")!);
    ws = new WebSocket(target.href, { origin: url.origin });
    ws.on("message", (d) => got.push(decodeWire(String(d)) as EngineMessage));
    await new Promise((r) => ws.once("open", r));
    ws.send(encodeWire({ type: "hello", version: 1 }));
  }, 60_000);

  afterAll(async () => {
    ws?.close();
    if (cli && cli.exitCode === null) {
      cli.kill("SIGINT");
      await new Promise((r) => cli.once("exit", r));
    }
  });

  const reply = async (id: number) => {
    await until(() => got.some((m) => m.type === "reply" && m.id === id), `reply ${id}`, 30_000);
    return got.find((m) => m.type === "reply" && m.id === id) as Extract<
      EngineMessage,
      { type: "reply" }
    >;
  };

  test("a module outside the allowed folders is refused before any of its code runs", async () => {
    const source =
      `Pipeline: { Blocks: [${join(outside, "evil.mjs")}] }\n` +
      "Clock: { Type: ScheduledTimer, DesiredRate: 100 }\n";
    ws.send(encodeWire({ type: "load", id: 1, file: join(dir, "evil.yaml"), source }));
    const r = await reply(1);
    expect(r.ok).toBe(false);
    expect(r.diagnostics?.[0]?.message).toMatch(
      /^cannot load user blocks from .*evil\.mjs: .*evil\.mjs is outside the folders this pipeline may run code from/,
    );
    expect(existsSync(join(outside, "ran"))).toBe(false);
  }, 60_000);

  test("the pipeline's own folder is allowed: its blocks load and the catalog lists them", async () => {
    const source = readFileSync(join(dir, "pipeline.yaml"), "utf8");
    ws.send(encodeWire({ type: "load", id: 2, file: join(dir, "pipeline.yaml"), source }));
    const r = await reply(2);
    expect(r.ok).toBe(true);
    expect(r.graph?.blocks.find((b) => b.name === "Smooth")?.type).toBe("Smoother");
    ws.send(encodeWire({ type: "catalog", id: 3 }));
    const c = await reply(3);
    const smoother = c.catalog?.types.find((t) => t.type === "Smoother");
    expect(smoother?.help).toContain("(User block from blocks/smoother.ts.)");
    expect(c.catalog?.types.some((t) => t.type === "Filter")).toBe(true);
  }, 60_000);
});
