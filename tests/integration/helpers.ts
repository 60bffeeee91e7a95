/** Helpers for integration tests that run the real CLI bundle (dist/, built by `npm test`). */
import { expect } from "vitest";
import { spawn, spawnSync, type ChildProcess } from "node:child_process";
import { existsSync, mkdtempSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { fileURLToPath } from "node:url";

export const ROOT = fileURLToPath(new URL("../../", import.meta.url));
export const CLI = join(ROOT, "dist", "cli.mjs");

export function requireBuild(): void {
  if (!existsSync(CLI) || !existsSync(join(ROOT, "dist", "engine.worker.mjs"))) {
    throw new Error("dist/ is missing: run `npm run build` (npm test does it) before these tests");
  }
}

export function tempDir(prefix = "mosaic-test-"): string {
  return mkdtempSync(join(tmpdir(), prefix));
}

export interface CliResult {
  code: number | null;
  stdout: string;
  stderr: string;
}

export function runCli(args: string[], opts: { cwd?: string; timeoutMs?: number } = {}): CliResult {
  const r = spawnSync(process.execPath, [CLI, ...args], {
    cwd: opts.cwd ?? ROOT,
    encoding: "utf8",
    timeout: opts.timeoutMs ?? 60_000,
    // `run --json` prints 20 telemetry lines a second: a run of a few seconds passes Node's 1 MiB.
    maxBuffer: 256 * 1024 * 1024,
    env: { ...process.env, NO_COLOR: "1" },
  });
  return { code: r.status, stdout: r.stdout, stderr: r.stderr };
}

export function startCli(args: string[], cwd = ROOT): ChildProcess {
  return spawn(process.execPath, [CLI, ...args], { cwd, env: { ...process.env, NO_COLOR: "1" } });
}

/** Parses the JSON lines of `mosaic run --json`. */
export function jsonLines(stdout: string): Record<string, unknown>[] {
  return stdout
    .split("\n")
    .filter((l) => l.startsWith("{"))
    .map((l) => JSON.parse(l) as Record<string, unknown>);
}

/**
 * A block that keeps up in real time: on time, or stumbling when one call (a catch-up frame after
 * the OS preempted the worker on a loaded CI machine) took longer than its events cover — never
 * lagging, never idle. Use for one telemetry snapshot of a real-time run; shares over the run
 * (or the virtual clock) are where strict "ontime" belongs.
 */
export const KEEPING_UP: readonly string[] = ["ontime", "stumbling"];

/** The wall clock in UNIX seconds (what a real-time block harness's clock follows). */
export const wall = (): number => (performance.timeOrigin + performance.now()) / 1000;

export const sleep = (ms: number): Promise<void> => new Promise((r) => setTimeout(r, ms));

/** Waits until `ok()` holds, polling every 5 ms; throws naming `what` after `ms`. */
export async function until(ok: () => boolean, what: string, ms = 5000): Promise<void> {
  const t0 = Date.now();
  while (!ok()) {
    if (Date.now() - t0 > ms) throw new Error(`timed out waiting for ${what}`);
    await sleep(5);
  }
}

/**
 * Stamps on a device's sample clock: one period apart, never wider (that would be a loss), never
 * backwards. A burst that arrives ahead of real time (a loaded machine) is stamped closer, never
 * ahead of its arrival, so only the median must be exactly one period.
 */
export function expectDeviceStamps(t: ArrayLike<number>, rate: number, n: number): void {
  const steps: number[] = [];
  for (let i = 1; i < n; i++) steps.push(t[i]! - t[i - 1]!);
  for (const dt of steps) expect(dt).toBeGreaterThanOrEqual(0);
  for (const dt of steps) expect(dt).toBeLessThanOrEqual(1 / rate + 1e-6);
  steps.sort((a, b) => a - b);
  expect(steps[steps.length >> 1]!).toBeCloseTo(1 / rate, 6);
}
