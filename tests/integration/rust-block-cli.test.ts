/**
 * Issue 18's acceptance for Rust blocks, exactly as docs/writing-blocks.md ("Rust blocks") says
 * it, in a temporary folder outside the repository: `mosaic new-block --rust tkeo DIR`, the cargo
 * build it prints, `tsc -p .` with the tsconfig.json it wrote, a pipeline naming
 * `tkeo/block.ts`, `mosaic test-block`, `mosaic validate` and a headless `mosaic run` whose log is
 * checked against the operator's closed form for a sine (ψ = A²·sin²(2πf/rate)). Then the module
 * rebuilt with another ABI version: the pipeline does not load, and the message names the module
 * and both versions.
 */
import { spawnSync } from "node:child_process";
import { readFileSync, rmSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { afterAll, beforeAll, describe, expect, it } from "vitest";
import { requireBuild, ROOT, runCli, tempDir } from "./helpers";

const RATE = 100;
const AMPLITUDE = 2;
const FREQUENCY = 5;

const PIPELINE = `Pipeline:
  Blocks: [tkeo/block.ts]

Clock: { Type: ScheduledTimer, DesiredRate: ${RATE} }
Sine: { Type: SinGenerator, Inputs: [Clock], Params: { Components: 2, Amplitude: ${AMPLITUDE}, Frequency: ${FREQUENCY} } }
Energy: { Type: Tkeo, Inputs: [Sine], Path: energy.csv }
`;

let dir: string;

function cargoBuild(crate: string): void {
  const r = spawnSync("cargo", ["build", "--release", "--target", "wasm32-unknown-unknown"], {
    cwd: crate,
    encoding: "utf8",
    timeout: 240_000,
  });
  if (r.status !== 0) throw new Error(`cargo build failed:\n${r.stderr}`);
}

beforeAll(() => {
  requireBuild();
  dir = tempDir("mosaic-rust-accept-");
  expect(dir.startsWith(ROOT)).toBe(false);
}, 60_000);

afterAll(() => {
  rmSync(dir, { recursive: true, force: true });
});

describe("a Rust block made with the documented commands, outside the repository", () => {
  it("is created, built, passes mosaic test-block and runs headless", () => {
    const made = runCli(["new-block", "--rust", "tkeo", "."], { cwd: dir });
    expect(made.stderr).toBe("");
    expect(made.code).toBe(0);
    expect(made.stdout).toContain(
      "cd tkeo && cargo build --release --target wasm32-unknown-unknown",
    );
    expect(made.stdout).toContain("Pipeline: { Blocks: [tkeo/block.ts] }");

    cargoBuild(join(dir, "tkeo"));
    writeFileSync(join(dir, "pipeline.yaml"), PIPELINE);

    // block.ts type-checks against the SDK with the tsconfig.json new-block wrote (strict).
    const tsc = spawnSync(
      process.execPath,
      [join(ROOT, "node_modules", "typescript", "bin", "tsc"), "-p", "."],
      {
        cwd: join(dir, "tkeo"),
        encoding: "utf8",
        timeout: 240_000,
      },
    );
    expect(tsc.stdout + tsc.stderr).toBe("");
    expect(tsc.status).toBe(0);

    const tested = runCli(["test-block", "tkeo/block.ts"], { cwd: dir, timeoutMs: 120_000 });
    expect(tested.stdout).toContain("Tkeo: all 6 checks pass");
    expect(tested.stdout).not.toContain("FAIL");
    expect(tested.code).toBe(0);

    const valid = runCli(["validate", "pipeline.yaml"], { cwd: dir });
    expect(valid.stdout + valid.stderr).toContain("pipeline.yaml: ok");
    expect(valid.code).toBe(0);

    const run = runCli(
      ["run", "pipeline.yaml", "--clock", "virtual", "--duration", "2", "--json"],
      {
        cwd: dir,
        timeoutMs: 120_000,
      },
    );
    expect(run.stderr).toBe("");
    expect(run.code).toBe(0);

    const rows = readFileSync(join(dir, "energy.csv"), "utf8")
      .trim()
      .split("\n")
      .map((line) => line.split(",").map(Number));
    expect(rows.length).toBe(2 * RATE + 1);
    // One sample late, zeros before the signal: the first output is 0 for every channel.
    expect(rows[0]!.slice(1)).toEqual([0, 0]);
    // From the third sample on, every channel's energy is A²·sin²(ω) (Kaiser 1990).
    const psi = AMPLITUDE ** 2 * Math.sin((2 * Math.PI * FREQUENCY) / RATE) ** 2;
    for (const row of rows.slice(2)) {
      expect(row.length).toBe(3);
      for (const v of row.slice(1)) expect(Math.abs(v - psi)).toBeLessThan(1e-9);
    }
  }, 600_000);

  it("rebuilt with another ABI version, the pipeline does not load and says why", () => {
    const abi = join(dir, "tkeo", "src", "abi.rs");
    const text = readFileSync(abi, "utf8");
    expect(text).toContain("ABI_VERSION: u32 = 1");
    writeFileSync(abi, text.replace("ABI_VERSION: u32 = 1", "ABI_VERSION: u32 = 2"));
    cargoBuild(join(dir, "tkeo"));

    const valid = runCli(["validate", "pipeline.yaml"], { cwd: dir });
    expect(valid.code).toBe(2);
    const said = valid.stdout + valid.stderr;
    expect(said).toContain("pipeline.yaml:2:");
    expect(said).toContain("tkeo/block.ts");
    expect(said).toContain(
      "tkeo.wasm speaks Rust block ABI version 2, but this MOSAIC speaks version 1",
    );
  }, 600_000);
});
