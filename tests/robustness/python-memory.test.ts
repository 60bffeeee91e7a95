/**
 * Issue 14, item 5: a sidecar cannot take the machine. Its memory is limited by the OS
 * (`MemoryLimit`, MB: RLIMIT_DATA, set in the sidecar before the user's module is imported), and
 * an allocation beyond it fails as a MemoryError that is reported as such — with the limit and the
 * param that changes it — and counted as an error; the process runs at a lower scheduling priority
 * than the engine (nice + 10), so a busy sidecar competes less with the pipeline's own threads.
 */
import { writeFileSync } from "node:fs";
import { join } from "node:path";
import { afterEach, describe, expect, test } from "vitest";
import {
  blockEvents,
  havePython,
  killMarked,
  newMarker,
  niceOf,
  requireBuild,
  startRun,
  summaryOf,
  telemetry,
  until,
  workdir,
} from "./python/support";

let marker = "";
afterEach(() => killMarked(marker));

describe.skipIf(!havePython)("sidecar resources", () => {
  test("MemoryLimit stops a 400 MB allocation under a 300 MB limit; the sidecar runs niced", async () => {
    requireBuild();
    const dir = workdir();
    marker = newMarker();
    writeFileSync(
      join(dir, "memory.yaml"),
      `
Timer: { Type: ScheduledTimer, DesiredRate: 20 }
Emg: { Type: EmgSimulator, Inputs: [Timer], Params: { Channels: 1 } }
Big:
  Type: Python
  Inputs: [Emg]
  Params: { Module: robust_funcs.py, Function: allocates, Init: init, Params: { mb: 400 }, MemoryLimit: 300 }
Small:
  Type: Python
  Inputs: [Emg]
  Params: { Module: robust_funcs.py, Function: allocates, Init: init, Params: { mb: 100 }, MemoryLimit: 300 }
`,
    );
    const cli = startRun([join(dir, "memory.yaml"), "--duration", "2.5", "--json"], dir, marker);
    const pidOf = (name: string): number | undefined => {
      const m = /pid (\d+)/.exec(
        telemetry(cli.stdout())
          .at(-1)
          ?.blocks.find((b) => b.name === name)?.text ?? "",
      );
      return m ? Number(m[1]) : undefined;
    };
    await until(() => pidOf("Big") !== undefined, 20_000, "the sidecar's pid", cli);
    const hostNice = niceOf(cli.child.pid!);
    expect(niceOf(pidOf("Big")!)).toBe(Math.min(19, hostNice + 10));
    const { code } = await cli.exited;
    const events = blockEvents(cli.stdout(), "Big").join("\n");
    expect(events).toMatch(
      /^error: MemoryError: .*the sidecar's memory limit \(MemoryLimit: 300 MB\)/m,
    );
    const summary = summaryOf(cli.stdout());
    const big = summary.blocks.find((b) => b.name === "Big")!;
    const small = summary.blocks.find((b) => b.name === "Small")!;
    expect(big.errors).toBeGreaterThan(10);
    expect(big.text).not.toMatch(/restart/);
    // Under the limit, allocations work.
    expect(small.errors, small.lastError).toBe(0);
    expect(small.events).toBeGreaterThan(30);
    expect(code, cli.stderr()).toBe(1);
  }, 40_000);
});
