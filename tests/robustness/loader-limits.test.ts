/**
 * Issue 14, items 1 and 14: loading is near-linear in the number of blocks (the topological order,
 * the runtime's lookups, YAML's duplicate-key check and aliases were quadratic), and what a file
 * may hold is bounded: size, blocks, values in Params, nesting, aliases (a "billion laughs").
 * Every refusal is fast and one positioned error that names the limit. Complexity is asserted as
 * ratios (4× the blocks in less than 6× the time), never as absolute times.
 */
import { describe, expect, test } from "vitest";
import { catalog } from "../../app/blocks/catalog";
import { VirtualClock } from "../../app/engine/clock";
import { formatDiagnostic } from "../../app/engine/diagnostics";
import { loadPipeline, LOAD_LIMITS, type PipelineSpec } from "../../app/engine/pipeline/loader";
import { Runtime } from "../../app/engine/runtime/runtime";
import { nodeResources } from "../../app/host/resources";
import { initDspForTests } from "../support/wasm";

initDspForTests();

/** A chain of `n` blocks: a timer, a simulator and Functions (every block one line). */
function chain(
  n: number,
  line = (i: number) => `  { Type: Function, Inputs: [B${i - 1}], Params: { Operation: abs } }`,
): string {
  const lines = [
    "Timer: { Type: ScheduledTimer, DesiredRate: 100 }",
    "B0: { Type: EmgSimulator, Inputs: [Timer], Params: { Channels: 2 } }",
  ];
  for (let i = 1; i < n - 1; i++) lines.push(`B${i}:${line(i)}`);
  return lines.join("\n") + "\n";
}

/** Above the default limits: the figures of issue 14 went to 130 000 blocks. */
const RAISED = { ...LOAD_LIMITS, maxChars: 20_000_000, maxBlocks: 200_000 };

/** Parses and validates `n` top-level entries that are not blocks (one error each); seconds. */
function loadTime(n: number): number {
  const lines: string[] = [];
  for (let i = 0; i < n; i++) lines.push(`k${i}: ${i}`);
  const source = lines.join("\n");
  const t0 = performance.now();
  const r = loadPipeline(source, "entries.yaml", catalog, RAISED);
  const t = (performance.now() - t0) / 1000;
  expect(r.diagnostics).toHaveLength(n);
  expect(r.diagnostics[n - 1]).toMatchObject({ code: "bad-block", line: n });
  return t;
}

/** Instantiates `spec` (Runtime.create, in topological order); seconds. */
async function createTime(spec: PipelineSpec): Promise<number> {
  const t0 = performance.now();
  const c = await Runtime.create({
    spec,
    catalog,
    clock: new VirtualClock(0),
    virtual: true,
    resources: nodeResources("/nonexistent"),
  });
  const t = (performance.now() - t0) / 1000;
  expect(c.diagnostics).toEqual([]);
  c.runtime!.dispose();
  return t;
}

const specOf = (source: string): PipelineSpec => {
  const r = loadPipeline(source, "chain.yaml", catalog);
  expect(r.diagnostics).toEqual([]);
  return r.spec!;
};

/** The best of `runs` (the machine is shared: the minimum is the least disturbed). */
async function best(runs: number, f: () => Promise<number>): Promise<number> {
  let m = Infinity;
  for (let i = 0; i < runs; i++) m = Math.min(m, await f());
  return m;
}

const errorsOf = (source: string) =>
  loadPipeline(source, "p.yaml", catalog).diagnostics.filter((d) => d.severity === "error");

/** Runs `f` and returns its result with the seconds it took. */
function timed<T>(f: () => T): [T, number] {
  const t0 = performance.now();
  const r = f();
  return [r, (performance.now() - t0) / 1000];
}

describe("loading is near-linear", () => {
  test("parsing and validating: 4× the entries in less than 6× the time", async () => {
    loadTime(1000); // warm up
    // YAML's duplicate-key check compared every key with every other; the collector counted
    // every diagnostic again for each block.
    const small = await best(2, async () => loadTime(8000));
    const large = await best(2, async () => loadTime(32_000));
    expect(
      large / small,
      `8000 entries ${small.toFixed(2)} s, 32000 entries ${large.toFixed(2)} s`,
    ).toBeLessThan(6);
  }, 120_000);

  test("instantiating in topological order: 4× the blocks in less than 6× the time", async () => {
    await createTime(specOf(chain(200))); // warm up
    const [a, b] = [specOf(chain(2500)), specOf(chain(10_000))];
    const small = await best(2, () => createTime(a));
    const large = await best(2, () => createTime(b));
    expect(
      large / small,
      `2500 blocks ${small.toFixed(2)} s, 10000 blocks ${large.toFixed(2)} s`,
    ).toBeLessThan(6);
  }, 120_000);

  test("aliases cost what they stand for: 4× the blocks with an alias each, less than 6× the time", async () => {
    const withAlias = (n: number) =>
      "Coef: &c [0.1, 0.2, 0.3]\n" +
      chain(
        n,
        (i) =>
          ` { Type: Filter, Inputs: [B${i - 1}], Params: { Numerator: *c, Denominator: [1] } }`,
      );
    // `Coef` is not a block: one error, the rest loads.
    const time = (n: number) => timed(() => errorsOf(withAlias(n)));
    time(100);
    const [e, small] = time(600);
    expect(e.map((d) => d.block)).toEqual(["Coef"]);
    let large = Infinity;
    for (let i = 0; i < 2; i++) large = Math.min(large, time(2400)[1]);
    expect(
      large / small,
      `600 blocks ${small.toFixed(2)} s, 2400 blocks ${large.toFixed(2)} s`,
    ).toBeLessThan(6);
  }, 120_000);

  test("blocks sharing one Path: one error each, 4× the blocks in less than 6× the time", () => {
    const samePath = (n: number) =>
      Array.from(
        { length: n },
        (_, i) => `T${i}: { Type: ScheduledTimer, DesiredRate: 10, Path: same.txt }`,
      ).join("\n") + "\n";
    // Each error looked its block up by a scan of the document's entries.
    const time = (n: number) => timed(() => errorsOf(samePath(n)));
    time(200);
    const [e, small] = time(2000);
    expect(e).toHaveLength(1999);
    expect(e[0]!.message).toContain("is also written by block 'T0' (Path at 1:");
    let large = Infinity;
    for (let i = 0; i < 2; i++) large = Math.min(large, time(8000)[1]);
    expect(
      large / small,
      `2000 blocks ${small.toFixed(2)} s, 8000 blocks ${large.toFixed(2)} s`,
    ).toBeLessThan(6);
  }, 120_000);
});

describe("limits: refused fast, positioned, naming the limit", () => {
  test("a file over the size limit is refused before it is parsed", () => {
    const big = "# " + "x".repeat(LOAD_LIMITS.maxChars) + "\n";
    const [e, s] = timed(() => errorsOf(big));
    expect(e).toHaveLength(1);
    expect(e[0]).toMatchObject({ code: "too-large", line: 1, col: 1 });
    expect(e[0]!.message).toBe(
      `the file has ${big.length} characters; a pipeline file may have at most ${LOAD_LIMITS.maxChars}`,
    );
    expect(s).toBeLessThan(0.5);
  });

  test("more blocks than the limit: one error at the first block past it", () => {
    const n = LOAD_LIMITS.maxBlocks + 5;
    const lines = ["T: { Type: ScheduledTimer, DesiredRate: 10 }"];
    for (let i = 1; i < n; i++)
      lines.push(`F${i}: { Type: Function, Inputs: [T], Params: { Operation: abs } }`);
    const e = errorsOf(lines.join("\n"));
    expect(e).toHaveLength(1);
    expect(e[0]).toMatchObject({
      code: "too-many-blocks",
      line: LOAD_LIMITS.maxBlocks + 1,
      col: 1,
    });
    expect(e[0]!.message).toContain(`more than ${LOAD_LIMITS.maxBlocks} blocks`);
  });

  test("a block's Params with more values than the limit", () => {
    const n = LOAD_LIMITS.maxParamsValues;
    const src =
      "T: { Type: ScheduledTimer, DesiredRate: 10 }\n" +
      `F: { Type: Filter, Inputs: [T], Params: { Numerator: [${"0,".repeat(n)}1], Denominator: [1] } }\n`;
    const e = errorsOf(src);
    expect(e).toHaveLength(1);
    expect(e[0]).toMatchObject({ code: "too-many-values", block: "F", line: 2, col: 41 });
    expect(e[0]!.message).toContain(`more than ${n} values`);
  });

  test("deep nesting says so with its line and column, not 'Maximum call stack size exceeded'", () => {
    const flow = `T: { Type: ScheduledTimer, DesiredRate: 10, Params: ${"[".repeat(20_000)}${"]".repeat(20_000)} }\n`;
    const [e, s] = timed(() => errorsOf(flow));
    expect(e.map(formatDiagnostic)).toEqual([
      `p.yaml:1:${52 + LOAD_LIMITS.maxDepth - 1}: error: nesting too deep: lists and mappings more than ${LOAD_LIMITS.maxDepth} levels inside one another (a pipeline needs about 6)`,
    ]);
    expect(s).toBeLessThan(10); // refused, not hung (under a second on a quiet machine)
    let block = "";
    for (let i = 0; i < 40; i++) block += `${" ".repeat(i)}k${i}:\n`;
    const e2 = errorsOf(block);
    expect(e2).toHaveLength(1);
    expect(e2[0]).toMatchObject({
      code: "nesting-too-deep",
      line: LOAD_LIMITS.maxDepth + 1,
      col: LOAD_LIMITS.maxDepth + 1,
    });
    expect(e2[0]!.message).not.toMatch(/call stack/);
  });

  test("a billion laughs is refused at once, at the alias that stands for too much", () => {
    let bomb = "a0: &a0 [lol, lol, lol, lol, lol, lol, lol, lol, lol, lol]\n";
    for (let i = 1; i < 10; i++)
      bomb += `a${i}: &a${i} [${Array(10)
        .fill(`*a${i - 1}`)
        .join(", ")}]\n`;
    // In Params, and outside any block's Params (nothing would expand it there).
    const inParams = `${bomb}T: { Type: ScheduledTimer, DesiredRate: 10 }\nF: { Type: Function, Inputs: [T], Params: { Operation: *a9 } }\n`;
    for (const src of [inParams, bomb]) {
      const [e, s] = timed(() => errorsOf(src));
      expect(s).toBeLessThan(0.5);
      expect(e).toHaveLength(1);
      // 10^6 values at a6 (line 7): the first alias over the limit is the first *a5 there.
      expect(e[0]).toMatchObject({ code: "alias-too-large", line: 7, col: 10 });
      expect(e[0]!.message).toBe(
        `alias *a5 stands for 1111111 values; an alias may stand for at most ${LOAD_LIMITS.maxParamsValues} (the values one block's Params may hold)`,
      );
    }
  });

  test("an alias that makes a block's Params too deep, or that contains itself", () => {
    let src = "a0: &a0 [1]\n";
    for (let i = 1; i < 40; i++) src += `a${i}: &a${i} [*a${i - 1}]\n`;
    const e = errorsOf(src);
    expect(e).toHaveLength(1);
    expect(e[0]!.code).toBe("nesting-too-deep");
    expect(e[0]!.message).toMatch(/^nesting too deep: alias \*a\d+ stands for/);
    const self = errorsOf("a: &a [1, *a]\n");
    expect(self[0]).toMatchObject({ code: "alias-too-large", line: 1, col: 11 });
  });

  test("aliases still work, expanded, within the limits", () => {
    const r = loadPipeline(
      `T: { Type: ScheduledTimer, DesiredRate: 10 }
E: { Type: EmgSimulator, Inputs: [T], Params: { Channels: 2 } }
F: { Type: Filter, Inputs: [E], Params: &c { Numerator: &n [0.5, 0.5], Denominator: [1] } }
G: { Type: Filter, Inputs: [F], Params: *c }
H: { Type: Filter, Inputs: [G], Params: { Numerator: *n, Denominator: [1] } }
`,
      "p.yaml",
      catalog,
    );
    expect(r.diagnostics).toEqual([]);
    const f = r.spec!.byName.get("F")!.params;
    expect(r.spec!.byName.get("G")!.params).toEqual(f);
    expect(r.spec!.byName.get("H")!.params).toEqual(f);
  });
});
