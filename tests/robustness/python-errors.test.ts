/**
 * Issue 14, item 4: Python failures count like any block error. Every exception raised by the
 * function and every death of the sidecar process is one error in the block's telemetry
 * (`errors`), is reported as an error event, and makes `mosaic run` exit 1 (README: exit 1 when a
 * block raised errors).
 */
import { writeFileSync } from "node:fs";
import { join } from "node:path";
import { describe, expect, test } from "vitest";
import {
  blockEvents,
  havePython,
  requireBuild,
  runCli,
  summaryOf,
  workdir,
} from "./python/support";

describe.skipIf(!havePython)("Python failures are block errors", () => {
  test("every exception and every sidecar crash is counted; the run exits 1", () => {
    requireBuild();
    const dir = workdir();
    writeFileSync(
      join(dir, "errors.yaml"),
      `
Timer: { Type: ScheduledTimer, DesiredRate: 50 }
Emg: { Type: EmgSimulator, Inputs: [Timer], Params: { Channels: 1 } }
Raises: { Type: Python, Inputs: [Emg], Params: { Module: robust_funcs.py, Function: raises, Init: init } }
Crashes: { Type: Python, Inputs: [Emg], Params: { Module: robust_funcs.py, Function: crashes, Init: init } }
`,
    );
    const r = runCli(["run", join(dir, "errors.yaml"), "--duration", "3.5", "--json"], {
      timeoutMs: 60_000,
    });
    const summary = summaryOf(r.stdout);
    expect(summary, r.stderr).toBeDefined();
    const raises = summary.blocks.find((b) => b.name === "Raises")!;
    const crashes = summary.blocks.find((b) => b.name === "Crashes")!;
    // Every exception: the block's own count (its status text) is the runtime's.
    const n = Number(/(\d+) errors \(last: ValueError: call \d+ fails/.exec(raises.text)?.[1]);
    expect(n, raises.text).toBeGreaterThan(80);
    expect(raises.errors).toBe(n);
    expect(raises.lastError).toMatch(/ValueError: call \d+ fails/);
    expect(blockEvents(r.stdout, "Raises").join("\n")).toMatch(
      /^error: ValueError: call 3 fails \(at .*robust_funcs\.py:\d+, in raises\)/m,
    );
    // Every crash: one error each (the status counts them as restarts), reported as an error
    // (events are rate-limited like any block's errors: one per 2 s).
    const died = blockEvents(r.stdout, "Crashes").filter((e) =>
      /exited with code 7; restarting in/.test(e),
    );
    expect(died.length).toBeGreaterThanOrEqual(1);
    expect(died.every((e) => e.startsWith("error: "))).toBe(true);
    const restarts = Number(/(\d+) restarts?\b/.exec(crashes.text)?.[1]);
    expect(restarts, crashes.text).toBeGreaterThanOrEqual(2);
    expect(crashes.errors).toBe(restarts);
    expect(crashes.lastError).toMatch(/exited with code 7; restarting in/);
    expect(summary.exitCode).toBe(1);
    expect(r.code).toBe(1);
  }, 60_000);
});
