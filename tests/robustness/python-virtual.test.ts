/**
 * Issue 14, item 13: under `--clock virtual` the engine waits for every Python call (virtual time
 * does not advance while one is outstanding), so every input is answered and a replay through
 * Python blocks is reproducible: two runs give byte-identical logs although the function's
 * duration varies at random (0–2 ms a call) between them.
 */
import { readFileSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { describe, expect, test } from "vitest";
import { blockEvents, havePython, requireBuild, runCli, workdir } from "./python/support";

const ROWS = 600;

describe.skipIf(!havePython)("Python under the virtual clock", () => {
  test("every input answered, logs byte-identical across runs", () => {
    requireBuild();
    const dir = workdir();
    // A 1 kHz recording played at its own timing: 5 rows per 5 ms batch, so the block gets frames
    // of several events, more than one call can take at a time.
    const rows = ["time_s,a,b"];
    for (let i = 0; i < ROWS; i++) {
      rows.push(`${(i / 1000).toFixed(3)},${Math.sin(i / 7).toFixed(6)},${(i % 13) - 6}`);
    }
    writeFileSync(join(dir, "rec.csv"), rows.join("\n") + "\n");
    writeFileSync(
      join(dir, "virtual.yaml"),
      `
Src: { Type: FilePlayer, Params: { File: rec.csv } }
A:
  Type: Python
  Inputs: [Src]
  Params: { Module: robust_funcs.py, Function: running_sum, Init: init, Params: { jitter_ms: 2 } }
  Path: a.txt
B:
  Type: Python
  Inputs: [A]
  Params: { Module: robust_funcs.py, Function: running_sum, Init: init, Params: { jitter_ms: 2 } }
  Path: b.txt
Direct: { Type: Function, Inputs: [Src], Params: { Operation: abs }, Path: direct.txt }
`,
    );
    const logs: string[][] = [];
    for (const run of [1, 2]) {
      const r = runCli(
        [
          "run",
          join(dir, "virtual.yaml"),
          "--clock",
          "virtual",
          "--json",
          "--log-dir",
          `run${run}`,
        ],
        { cwd: dir, timeoutMs: 60_000 },
      );
      expect(r.code, r.stderr).toBe(0);
      expect(blockEvents(r.stdout, "A").join("\n")).not.toMatch(/not awaited/);
      logs.push(
        ["a.txt", "b.txt", "direct.txt"].map((f) =>
          readFileSync(join(dir, `run${run}`, f), "utf8"),
        ),
      );
    }
    const [a, b, direct] = logs[0]!;
    for (const [name, text] of [
      ["A", a!],
      ["B", b!],
      ["Direct", direct!],
    ] as const) {
      const lines = text.trimEnd().split("\n");
      expect(lines.length, name).toBe(ROWS);
    }
    // Every input answered, in order: the call counter (last column) of the last line is ROWS.
    expect(a!.trimEnd().split("\n").at(-1)!.split(",").at(-1)).toBe(String(ROWS));
    expect(b!.trimEnd().split("\n").at(-1)!.split(",").at(-1)).toBe(String(ROWS));
    expect(logs[1]).toEqual(logs[0]);
  }, 60_000);
});
