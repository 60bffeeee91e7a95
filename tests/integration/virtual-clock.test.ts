import { readFileSync, readdirSync } from "node:fs";
import { join } from "node:path";
import { beforeAll, describe, expect, test } from "vitest";
import { jsonLines, requireBuild, runCli, tempDir } from "./helpers";

beforeAll(requireBuild);

describe("virtual clock", () => {
  test("the same pipeline and input file give byte-identical logs twice", () => {
    const runs = [tempDir(), tempDir()].map((dir) => {
      const r = runCli([
        "run",
        "pipelines/examples/replay-envelope.yaml",
        "--clock",
        "virtual",
        "--log-dir",
        dir,
        "--json",
      ]);
      expect(r.stderr).toBe("");
      expect(r.code).toBe(0);
      const summary = jsonLines(r.stdout).find((l) => l.type === "summary") as { reason: string };
      expect(summary.reason).toBe("finished");
      const files = readdirSync(join(dir, "replay-logs")).sort();
      return {
        dir,
        files,
        text: files.map((f) => readFileSync(join(dir, "replay-logs", f), "utf8")),
      };
    });
    expect(runs[0]!.files).toEqual(["Envelope.txt", "Sampled.txt"]);
    expect(runs[1]!.files).toEqual(runs[0]!.files);
    expect(runs[1]!.text[0]).toBe(runs[0]!.text[0]);
    expect(runs[1]!.text[1]).toBe(runs[0]!.text[1]);
    // The whole recording came through: 28,519 samples, original timing from time 0.
    const env = runs[0]!.text[0]!.trimEnd().split("\n");
    expect(env).toHaveLength(28519);
    expect(env[0]!.startsWith("0.000000,")).toBe(true);
    expect(env[1]!.startsWith("0.001000,")).toBe(true);
    expect(env.at(-1)!.startsWith("28.518000,")).toBe(true);
    const sampled = runs[0]!.text[1]!.trimEnd().split("\n");
    expect(sampled.length).toBeGreaterThan(1400);
  });
});
