/**
 * Fuzzes the loader with random mutations of valid pipeline files: it must never throw, and every
 * problem must come back as a diagnostic that names the file, a position and a message.
 */
import { readdirSync, readFileSync } from "node:fs";
import { dirname, join } from "node:path";
import fc from "fast-check";
import { beforeAll, describe, expect, test } from "vitest";
import { catalog } from "../../app/blocks/catalog";
import { VirtualClock } from "../../app/engine/clock";
import { loadPipeline } from "../../app/engine/pipeline/loader";
import { Runtime } from "../../app/engine/runtime/runtime";
import { nodeResources } from "../../app/host/resources";
import { initDspForTests } from "../support/wasm";
import { ROOT } from "./helpers";

function pipelineFiles(): { file: string; text: string }[] {
  const out: { file: string; text: string }[] = [];
  const walk = (d: string): void => {
    for (const e of readdirSync(d, { withFileTypes: true })) {
      if (e.isDirectory()) walk(join(d, e.name));
      else if (e.name.endsWith(".yaml"))
        out.push({ file: join(d, e.name), text: readFileSync(join(d, e.name), "utf8") });
    }
  };
  walk(join(ROOT, "pipelines"));
  // Files in the original MOSAIC's layouts: mutations there go through the YAML pre-pass.
  walk(join(ROOT, "tests/fixtures/mosaic-original"));
  return out;
}

const YAML_CHARS = [
  ":",
  "-",
  "[",
  "]",
  "{",
  "}",
  ",",
  '"',
  "'",
  "#",
  "\n",
  " ",
  "\t",
  "&",
  "*",
  "!",
  "|",
  ">",
  "%",
  "@",
  "?",
  "0",
  "1e999",
  "-.inf",
  ".nan",
  "~",
  "null",
  "x",
  "é",
  "\u0000",
  "\\",
];

/** One random edit of a source text. */
const mutation = fc.oneof(
  // delete a range
  fc.record({
    kind: fc.constant("delete" as const),
    at: fc.nat(),
    len: fc.integer({ min: 1, max: 40 }),
  }),
  // insert YAML-significant characters
  fc.record({
    kind: fc.constant("insert" as const),
    at: fc.nat(),
    text: fc
      .array(fc.constantFrom(...YAML_CHARS), { minLength: 1, maxLength: 5 })
      .map((a) => a.join("")),
  }),
  // duplicate a line
  fc.record({ kind: fc.constant("dupline" as const), line: fc.nat() }),
  // swap two lines
  fc.record({ kind: fc.constant("swap" as const), a: fc.nat(), b: fc.nat() }),
  // replace a number by something of another type
  fc.record({
    kind: fc.constant("renumber" as const),
    nth: fc.nat(),
    text: fc.constantFrom(
      "abc",
      "[1, 2]",
      "{ a: 1 }",
      "-1",
      "0",
      "1e308",
      "",
      "true",
      "null",
      "3.5",
    ),
  }),
  // truncate
  fc.record({ kind: fc.constant("truncate" as const), at: fc.nat() }),
  // replace a word
  fc.record({
    kind: fc.constant("reword" as const),
    nth: fc.nat(),
    text: fc.constantFrom(
      "Type",
      "Inputs",
      "Params",
      "Timer",
      "-Timer",
      "Filter",
      "Fliter",
      "Path",
      "Worker",
      "Queue",
      "DesiredRate",
      "Layout",
      "x.y",
      "Emg.gesture",
      "Sink",
    ),
  }),
);

type Mutation = typeof mutation extends fc.Arbitrary<infer T> ? T : never;

function apply(text: string, m: Mutation): string {
  const lines = text.split("\n");
  switch (m.kind) {
    case "delete": {
      const at = m.at % (text.length + 1);
      return text.slice(0, at) + text.slice(at + m.len);
    }
    case "insert": {
      const at = m.at % (text.length + 1);
      return text.slice(0, at) + m.text + text.slice(at);
    }
    case "dupline": {
      const i = m.line % lines.length;
      lines.splice(i, 0, lines[i]!);
      return lines.join("\n");
    }
    case "swap": {
      const a = m.a % lines.length;
      const b = m.b % lines.length;
      [lines[a], lines[b]] = [lines[b]!, lines[a]!];
      return lines.join("\n");
    }
    case "renumber": {
      const nums = [...text.matchAll(/-?\d+(\.\d+)?(e-?\d+)?/g)];
      if (nums.length === 0) return text;
      const n = nums[m.nth % nums.length]!;
      return text.slice(0, n.index) + m.text + text.slice(n.index! + n[0].length);
    }
    case "truncate":
      return text.slice(0, m.at % (text.length + 1));
    case "reword": {
      const words = [...text.matchAll(/[A-Za-z_][A-Za-z0-9_]*/g)];
      if (words.length === 0) return text;
      const w = words[m.nth % words.length]!;
      return text.slice(0, w.index) + m.text + text.slice(w.index! + w[0].length);
    }
  }
}

const files = pipelineFiles();

describe("loader fuzzing", () => {
  beforeAll(initDspForTests);

  test("there are pipelines to mutate", () => {
    expect(files.length).toBeGreaterThanOrEqual(4);
  });

  test("random mutations of valid files: never an exception, always positioned diagnostics", async () => {
    let invalid = 0;
    let instantiated = 0;
    await fc.assert(
      fc.asyncProperty(
        fc.nat({ max: files.length - 1 }),
        fc.array(mutation, { minLength: 1, maxLength: 4 }),
        async (fi, ms) => {
          const { file, text } = files[fi]!;
          const src = ms.reduce(apply, text);
          const r = loadPipeline(src, file, catalog);
          for (const d of r.diagnostics) {
            expect(d.file).toBe(file);
            expect(d.message.length).toBeGreaterThan(0);
            expect(d.line).toBeGreaterThanOrEqual(0);
            expect(d.col).toBeGreaterThanOrEqual(0);
            expect(d.code).not.toBe("internal");
            if (d.severity === "error") expect(d.line).toBeGreaterThan(0);
          }
          if (!r.ok) {
            invalid++;
            expect(r.diagnostics.some((d) => d.severity === "error")).toBe(true);
            return;
          }
          // What loads must also instantiate or fail with diagnostics (never throw).
          const created = await Runtime.create({
            spec: r.spec!,
            catalog,
            clock: new VirtualClock(0),
            virtual: true,
            resources: nodeResources(dirname(file)),
            ignorePlacement: true,
          });
          for (const d of created.diagnostics) {
            expect(d.message.length).toBeGreaterThan(0);
            expect(d.block).toBeDefined();
          }
          if (created.runtime) {
            instantiated++;
            created.runtime.dispose();
          }
        },
      ),
      { numRuns: 400, seed: 20261122 },
    );
    expect(invalid).toBeGreaterThan(50);
    expect(instantiated).toBeGreaterThan(10);
  }, 120_000);
});
