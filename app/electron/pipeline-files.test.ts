import { mkdtempSync, readFileSync, rmSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import {
  loadFailureText,
  MAX_PIPELINE_BYTES,
  readPipelineFile,
  withYamlExtension,
  writePipelineFile,
} from "./pipeline-files";

let dir: string;
beforeAll(() => {
  dir = mkdtempSync(join(tmpdir(), "mosaic-pipeline-files-"));
});
afterAll(() => rmSync(dir, { recursive: true, force: true }));

describe("pipeline files", () => {
  test("reads text; refuses folders, missing, binary and oversized files with a reason", async () => {
    const f = join(dir, "ok.yaml");
    writeFileSync(f, "Blocks: {}\n");
    await expect(readPipelineFile(f)).resolves.toBe("Blocks: {}\n");
    await expect(readPipelineFile(join(dir, "missing.yaml"))).rejects.toThrow(/cannot open/);
    await expect(readPipelineFile(dir)).rejects.toThrow(/not a file/);
    const bin = join(dir, "bin.yaml");
    writeFileSync(bin, new Uint8Array([1, 0, 2]));
    await expect(readPipelineFile(bin)).rejects.toThrow(/not a text/);
    const big = join(dir, "big.yaml");
    writeFileSync(big, Buffer.alloc(MAX_PIPELINE_BYTES + 1, 32));
    await expect(readPipelineFile(big)).rejects.toThrow(/at most/);
  });

  test("writes, adding .yaml when the name has no extension", async () => {
    expect(withYamlExtension("/a/b")).toBe("/a/b.yaml");
    expect(withYamlExtension("/a/b.yml")).toBe("/a/b.yml");
    const written = await writePipelineFile(join(dir, "saved"), "x: 1\n");
    expect(written).toBe(join(dir, "saved.yaml"));
    expect(readFileSync(written, "utf8")).toBe("x: 1\n");
  });

  test("load failures list the errors first, capped", () => {
    const d = (severity: string, line: number, message: string) => ({
      severity,
      message,
      file: "/p/x.yaml",
      line,
      col: 3,
    });
    const text = loadFailureText({
      ok: false,
      diagnostics: [
        d("warning", 2, "positional Params"),
        { ...d("error", 5, "unknown block type 'Filtre'"), suggestion: "Filter" },
      ],
    });
    expect(text.split("\n")).toEqual([
      "line 5:3: error: unknown block type 'Filtre'; did you mean 'Filter'?",
      "line 2:3: warning: positional Params",
    ]);
    expect(loadFailureText({ ok: false })).toBe("the engine did not say why");
    expect(loadFailureText({ ok: false, message: "busy" })).toBe("busy");
    const many = loadFailureText({
      ok: false,
      diagnostics: Array.from({ length: 20 }, (_, i) => d("error", i + 1, `e${i}`)),
    });
    expect(many.split("\n")).toHaveLength(9);
    expect(many).toMatch(/… and 12 more$/);
  });
});
