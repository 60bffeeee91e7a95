/** `mosaic format`: the editor's canonical round trip from the command line (real CLI bundle). */
import { readdirSync, readFileSync, statSync, writeFileSync } from "node:fs";
import { join, relative } from "node:path";
import fc from "fast-check";
import { beforeAll, describe, expect, it } from "vitest";
import { catalog } from "../../app/blocks/catalog";
import { PipelineDocument, referencedBlock } from "../../app/engine/pipeline/document";
import { loadPipeline } from "../../app/engine/pipeline/loader";
import { requireBuild, ROOT, runCli, tempDir } from "./helpers";

function yamlFiles(dir: string): string[] {
  const out: string[] = [];
  for (const name of readdirSync(dir).sort()) {
    const p = join(dir, name);
    if (statSync(p).isDirectory()) {
      if (name !== "data" && name !== "schema") out.push(...yamlFiles(p));
    } else if (name.endsWith(".yaml")) out.push(p);
  }
  return out;
}

const COMMENTED = `# A pipeline with comments.
Timer: { Type: ScheduledTimer, DesiredRate: 100 } # the clock

Emg:
  Type: EmgSimulator
  Inputs: [ Timer ]   # padded, with spaces before the comment
  Params:
    Channels: 2
Sink: { Type: Sink, Inputs: [Emg] }`;

describe("mosaic format", () => {
  beforeAll(() => requireBuild());

  it("every example pipeline is already canonical (--check: exit 0, nothing written)", () => {
    const files = yamlFiles(join(ROOT, "pipelines")).map((f) => relative(ROOT, f));
    expect(files.length).toBeGreaterThan(10);
    const before = files.map((f) => readFileSync(join(ROOT, f), "utf8"));
    const r = runCli(["format", "--check", ...files], { timeoutMs: 120_000 });
    expect(r.stderr).toBe("");
    expect(r.code).toBe(0);
    for (const f of files) expect(r.stdout).toContain(`${f}: unchanged`);
    files.forEach((f, i) => expect(readFileSync(join(ROOT, f), "utf8")).toBe(before[i]));
  });

  it("--check reports a file that would change (exit 1); format writes it; a second run is a no-op", () => {
    const dir = tempDir();
    const f = join(dir, "p.yaml");
    writeFileSync(f, COMMENTED);
    const check = runCli(["format", "--check", f]);
    expect(check.code).toBe(1);
    expect(check.stdout).toContain(`${f}: would change`);
    expect(readFileSync(f, "utf8")).toBe(COMMENTED);

    const r = runCli(["format", f]);
    expect(r.code).toBe(0);
    expect(r.stdout).toContain(`${f}: formatted`);
    // Only the final line break was added: comments, spacing and styles are kept.
    expect(readFileSync(f, "utf8")).toBe(`${COMMENTED}\n`);

    const again = runCli(["format", "--check", f]);
    expect(again.code).toBe(0);
    expect(again.stdout).toContain(`${f}: unchanged`);
  });

  it("keeps CRLF files as they are", () => {
    const dir = tempDir();
    const f = join(dir, "crlf.yaml");
    const src = `${COMMENTED}\n`.replace(/\n/g, "\r\n");
    writeFileSync(f, src);
    const r = runCli(["format", f]);
    expect(r.code).toBe(0);
    expect(readFileSync(f, "utf8")).toBe(src);
  });

  it("never writes an invalid file: positioned messages, exit 2 (the valid ones are still done)", () => {
    const dir = tempDir();
    const bad = join(dir, "bad.yaml");
    const good = join(dir, "good.yaml");
    const badSrc =
      "Timer: { Type: ScheduledTimer, DesiredRate: 100 }\nSink: { Type: Sink, Inputs: [Timr] }";
    writeFileSync(bad, badSrc);
    writeFileSync(good, COMMENTED);
    const r = runCli(["format", bad, good]);
    expect(r.code).toBe(2);
    expect(r.stderr).toContain(`${bad}:2:`);
    expect(r.stderr).toMatch(/Timr/);
    expect(r.stderr).toContain(`${bad}: invalid (1 error), not formatted`);
    expect(readFileSync(bad, "utf8")).toBe(badSrc);
    expect(readFileSync(good, "utf8")).toBe(`${COMMENTED}\n`);

    const syntax = join(dir, "syntax.yaml");
    writeFileSync(syntax, "Timer: { Type: ScheduledTimer\n");
    const s = runCli(["format", "--check", syntax]);
    expect(s.code).toBe(2);
    expect(s.stderr).toMatch(/syntax\.yaml:\d+:\d+/);
  });

  it("needs a file", () => {
    const r = runCli(["format"]);
    expect(r.code).toBe(2);
    expect(r.stderr).toContain("usage: mosaic format");
    expect(runCli(["--help"]).stdout).toContain("mosaic format FILE... [--check]");
  });
});

/**
 * The editor's document model against the loader with the real catalog (engine tests may not
 * import the blocks): edits that keep the wiring whole keep every example and fixture valid.
 */
describe("PipelineDocument edits load with the real catalog", () => {
  const fixtures = join(ROOT, "app/engine/pipeline/fixtures");
  const files = [...yamlFiles(join(ROOT, "pipelines")), ...yamlFiles(fixtures)];
  const cases = files.map((f) => ({ name: relative(ROOT, f), text: readFileSync(f, "utf8") }));
  const errorsOf = (text: string, file: string) =>
    loadPipeline(text, file, catalog).diagnostics.filter((d) => d.severity === "error");

  it("every file loads as it is", () => {
    for (const c of cases) expect(errorsOf(c.text, c.name), c.name).toEqual([]);
  });

  it("rename, duplicate, add and remove (of a block nothing reads) keep each file valid", () => {
    for (const c of cases) {
      const names = PipelineDocument.parse(c.text, c.name).blockNames();
      for (const b of names) {
        const d = PipelineDocument.parse(c.text, c.name);
        d.renameBlock(b, d.freshName(`${b}_renamed`));
        expect(errorsOf(d.toString(), c.name), `${c.name}: rename ${b}`).toEqual([]);
        const e = PipelineDocument.parse(c.text, c.name);
        const copy = e.freshName(b);
        e.duplicateBlock(b, copy);
        e.addBlock(e.freshName("Probe"), "Sink", { inputs: [copy], layout: { x: 1, y: 2 } });
        expect(errorsOf(e.toString(), c.name), `${c.name}: duplicate ${b}`).toEqual([]);
        const used = names.some((n) => e.inputsOf(n).some((s) => referencedBlock(s) === b));
        if (!used) {
          const r = PipelineDocument.parse(c.text, c.name);
          try {
            r.removeBlock(b);
          } catch (err) {
            expect((err as Error).message).toMatch(/has no anchor/);
            continue;
          }
          if (r.blockNames().length > 0) {
            expect(errorsOf(r.toString(), c.name), `${c.name}: remove ${b}`).toEqual([]);
          }
        }
      }
    }
  });

  it("converts positional Params on request (the legacy example stays valid)", () => {
    const c = cases.find((x) => x.name.includes("legacy"))!;
    const d = PipelineDocument.parse(c.text, c.name);
    for (const b of d.blockNames())
      if (d.block(b).positionalParams) d.convertLegacyParams(b, catalog);
    expect(d.blockNames().some((b) => d.block(b).positionalParams)).toBe(false);
    expect(errorsOf(d.toString(), c.name)).toEqual([]);
    expect(d.validate(catalog).filter((x) => x.code === "legacy-converted")).toEqual([]);
    d.setParam("amplified", "Value", 6);
    expect(d.toString()).toContain(
      "amplified: { Type: Function, Inputs: [ sinusoid ], Params: { Operation: multiply, Value: 6 } }",
    );
  });

  it("random sequences of wiring-preserving edits keep a valid file valid (fast-check)", () => {
    const op = fc.oneof(
      fc.record({ k: fc.constant("rename" as const), i: fc.nat(), s: fc.string({ maxLength: 3 }) }),
      fc.record({ k: fc.constant("dup" as const), i: fc.nat() }),
      fc.record({ k: fc.constant("probe" as const), i: fc.nat() }),
      fc.record({ k: fc.constant("removeLeaf" as const), i: fc.nat() }),
      fc.record({
        k: fc.constant("layout" as const),
        i: fc.nat(),
        x: fc.integer(),
        y: fc.integer(),
      }),
    );
    fc.assert(
      fc.property(fc.constantFrom(...cases), fc.array(op, { maxLength: 8 }), (c, ops) => {
        const d = PipelineDocument.parse(c.text, c.name);
        for (const o of ops) {
          const names = d.blockNames();
          const b = names[o.i % names.length]!;
          if (o.k === "rename") d.renameBlock(b, d.freshName(`${b}_${o.s}`));
          else if (o.k === "dup") d.duplicateBlock(b, d.freshName(b));
          else if (o.k === "probe") d.addBlock(d.freshName("Probe"), "Sink", { inputs: [b] });
          else if (o.k === "layout") d.setLayout(b, { x: o.x, y: o.y });
          else {
            const used = names.some((n) => d.inputsOf(n).some((s) => referencedBlock(s) === b));
            if (used || names.length < 2) continue;
            try {
              d.removeBlock(b);
            } catch (err) {
              expect((err as Error).message).toMatch(/has no anchor/);
            }
          }
          expect(errorsOf(d.toString(), c.name), `${c.name}: ${o.k} ${b}`).toEqual([]);
        }
      }),
      { numRuns: 60 },
    );
  });
});
