/**
 * Every example in pipelines/devices/ runs without its hardware: `mosaic run FILE
 * --simulate-devices` for a second exits 0, every device block became a simulator of the same
 * shape (one info line each), and no block reported an error.
 */
import { readdirSync } from "node:fs";
import { join } from "node:path";
import { describe, expect, test } from "vitest";
import { jsonLines, requireBuild, ROOT, runCli } from "./helpers";

const DIR = join(ROOT, "pipelines", "devices");
const FILES = readdirSync(DIR).filter((f) => f.endsWith(".yaml"));

describe("pipelines/devices under --simulate-devices", () => {
  test("there is an example per device family", () => {
    for (const f of ["delsys", "muovi", "quattrocento", "sessantaquattro", "hannes", "nilspod"]) {
      expect(FILES, f).toContain(`${f}.yaml`);
    }
    expect(FILES).toContain("myo.yaml");
    expect(FILES).toContain("dlr-adcbt.yaml");
    expect(FILES).toContain("brainflow-synthetic.yaml");
  });

  test.each(FILES)("%s runs for a second, every block without errors", (file) => {
    requireBuild();
    const r = runCli(
      [
        "run",
        join("pipelines", "devices", file),
        "--simulate-devices",
        "--duration",
        "1",
        "--json",
      ],
      { timeoutMs: 60_000 },
    );
    expect(r.code, r.stderr.slice(-2000)).toBe(0);
    // (BrainFlow's synthetic board is a simulator already: nothing to replace.)
    if (file !== "brainflow-synthetic.yaml") expect(r.stderr).toMatch(/simulated by|replaced by/);
    const summary = jsonLines(r.stdout).find((l) => l.type === "summary") as
      { blocks: { name: string; errors: number }[] } | undefined;
    expect(summary, r.stdout.slice(-1000)).toBeDefined();
    expect(summary!.blocks.filter((b) => b.errors > 0).map((b) => b.name)).toEqual([]);
  });
});
