/**
 * Issue 14, item 8: an error about a file a pipeline reads quotes at most a short, escaped
 * excerpt of it: a FilePlayer pointed at `/etc/shadow`-like text named the file's whole first
 * line as its "columns", and a model file's JSON error carried the engine's own excerpt of it.
 * Here the file is the user's own choice (as with `mosaic run`), so only the excerpts are at
 * stake: no more than a few characters of one line, control characters escaped.
 */
import { mkdtempSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { describe, expect, test } from "vitest";
import { catalog } from "../../app/blocks/catalog";
import { parseModelFile } from "../../app/blocks/learning/model-file";
import { parseDelimited } from "../../app/blocks/sources/delimited-text";
import { VirtualClock } from "../../app/engine/clock";
import { loadPipeline } from "../../app/engine/pipeline/loader";
import { Runtime } from "../../app/engine/runtime/runtime";
import { nodeResources } from "../../app/host/resources";
import { initDspForTests } from "../support/wasm";

initDspForTests();

const HASH = "$6$Qw3rTyUi0pAsDfGhJkLzXcVbNm1234567890abcdefghijklmnopqrstuvw";
const SHADOW = [
  `root:${HASH}:19000:0:99999:7:::`,
  "daemon:*:19000:0:99999:7:::",
  "bin:*:19000:0:99999:7:::",
].join("\n");
const dir = mkdtempSync(join(tmpdir(), "mosaic-excerpt-"));
writeFileSync(join(dir, "shadow"), SHADOW + "\n");
writeFileSync(
  join(dir, "ansi.csv"),
  "\u001b[2J\u001b[31mred,b,c,d,e,f,g,h,i,j,k,l\n1,2,3,4,5,6,7,8,9,10,11,12\n",
);

/** Every error the pipeline's blocks raise when instantiated. */
async function createErrors(block: string): Promise<string[]> {
  const r = loadPipeline(
    `T: { Type: ScheduledTimer, DesiredRate: 100 }\nS: { Type: SinGenerator, Inputs: [T] }\nX: ${block}\n`,
    join(dir, "p.yaml"),
    catalog,
  );
  expect(r.diagnostics.filter((d) => d.severity === "error")).toEqual([]);
  const c = await Runtime.create({
    spec: r.spec!,
    catalog,
    clock: new VirtualClock(0),
    virtual: true,
    resources: nodeResources(dir),
  });
  c.runtime?.dispose();
  return c.diagnostics.map((d) => d.message);
}

/** Nothing of the file but an excerpt of at most `max` characters of its first line. */
function expectExcerptOnly(message: string, max = 30): void {
  expect(message).not.toContain(HASH.slice(0, max + 1));
  expect(message).not.toContain("daemon");
  expect(message).not.toContain("19000:0:99999");
  expect(message).not.toMatch(/[\u0000-\u001f\u007f]/);
}

describe("errors about a file show a short, escaped excerpt at most", () => {
  test("FilePlayer: its columns are named in excerpts, a few of them", async () => {
    for (const params of ["Columns: [Missing]", "TimeColumn: t", "Columns: [5]"]) {
      const [m] = await createErrors(
        `{ Type: FilePlayer, Inputs: [T], Params: { File: shadow, Header: true, ${params} } }`,
      );
      expect(m, params).toBeDefined();
      expectExcerptOnly(m!);
    }
    const [m] = await createErrors(
      "{ Type: FilePlayer, Inputs: [T], Params: { File: ansi.csv, Columns: [zz] } }",
    );
    expectExcerptOnly(m!);
    expect(m).toContain("\\u001b[2J");
    expect(m).toContain("(12 in all)");
  });

  test("delimited text: a field that is not a number, quoted short and escaped", () => {
    expect(() =>
      parseDelimited(`a,b\n1,${"\u001b".repeat(3)}${"x".repeat(100)}\n`, {
        file: "f.csv",
        header: "auto",
        delimiter: "auto",
        columns: undefined,
        timeColumn: undefined,
      }),
    ).toThrow(/field 2 \(column "b"\) is "\\u001b\\u001b\\u001bx{27}…", which is not a number/);
  });

  test("model files: invalid JSON says what went wrong where, not what the text is", async () => {
    expect(() => parseModelFile(SHADOW, "m.json")).toThrow(
      /^model file 'm.json': not a MOSAIC model file: invalid JSON \(Unexpected token 'r'\)$/,
    );
    expect(() => parseModelFile('{"format": "mosaic-model", "x": 1,\n ]', "m.json")).toThrow(
      /invalid JSON \(Expected double-quoted property name in JSON at position 36\)$/,
    );
    expect(() => parseModelFile("\u0001", "m.json")).toThrow(/Unexpected token '\\u0001'/);
    for (const type of ["IncrementalPredictor", "BatchPredictor"]) {
      const errs = await createErrors(
        `{ Type: ${type}, Inputs: [S${type === "BatchPredictor" ? "" : ", S"}], Params: { File: shadow${type === "BatchPredictor" ? ", Outputs: 1" : ""} } }`,
      );
      expect(errs.length, type).toBeGreaterThan(0);
      for (const m of errs) expectExcerptOnly(m, 0);
    }
  });
});
