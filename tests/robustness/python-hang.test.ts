/**
 * Issue 14, item 3: a Python call that never returns is not invisible. While it runs past
 * `Budget` it is counted as over budget (and the status says how long it has been running); past
 * the hard limit (`HardLimit`, default 10 × Budget and at least 2 s) it is reported as an error
 * event naming the limit, the process is killed and restarted with backoff, and the block goes
 * on (and hangs again: the fixture's fresh state hangs from its third call on).
 */
import { writeFileSync } from "node:fs";
import { join } from "node:path";
import { afterEach, describe, expect, test } from "vitest";
import {
  blockEvents,
  havePython,
  killMarked,
  newMarker,
  requireBuild,
  startRun,
  summaryOf,
  telemetry,
  until,
  workdir,
} from "./python/support";
import { KEEPING_UP } from "../integration/helpers";

let marker = "";
afterEach(() => killMarked(marker));

describe.skipIf(!havePython)("a hung Python call", () => {
  test("is counted while it runs, then killed at the hard limit, reported and restarted", async () => {
    requireBuild();
    const dir = workdir();
    marker = newMarker();
    // 50 Hz: Budget one period (20 ms), so the default hard limit is max(10 × 20 ms, 2 s) = 2 s.
    writeFileSync(
      join(dir, "hang.yaml"),
      `
Timer: { Type: ScheduledTimer, DesiredRate: 50 }
Emg: { Type: EmgSimulator, Inputs: [Timer], Params: { Channels: 2 } }
Py: { Type: Python, Inputs: [Emg], Params: { Module: robust_funcs.py, Function: hang, Init: init } }
Other: { Type: Function, Inputs: [Emg], Params: { Operation: abs } }
`,
    );
    const cli = startRun([join(dir, "hang.yaml"), "--json"], dir, marker);
    const py = () =>
      telemetry(cli.stdout())
        .map((t) => t.blocks.find((b) => b.name === "Py")!)
        .filter(Boolean);
    // Before the kill: the running call already counts, and the status says it is running.
    await until(
      () => py().some((b) => /running for/.test(b.text)),
      20_000,
      "the status of the running call",
      cli,
    );
    const during = py().at(-1)!;
    expect(during.text).toMatch(/1 over budget \(20\.0 ms\)/);
    expect(during.text).toMatch(/call running for \d/);
    // The hard limit: an error event naming it, a kill and a restart under a new pid.
    await until(
      () => blockEvents(cli.stdout(), "Py").some((e) => /restarted \(pid \d+\)/.test(e)),
      20_000,
      "the restart",
      cli,
    );
    cli.child.kill("SIGINT");
    const { code } = await cli.exited;
    const events = blockEvents(cli.stdout(), "Py").join("\n");
    expect(events).toMatch(
      /error: .*call ran longer than its hard limit of 2 s \(HardLimit\).*killed.*restarting in 0\.5 s/,
    );
    const last = summaryOf(cli.stdout()).blocks.find((b) => b.name === "Py")!;
    expect(last.errors).toBeGreaterThanOrEqual(1);
    expect(last.text).toMatch(/[1-9]\d* restarts?\b/);
    expect(last.text).toMatch(/[1-9]\d* over budget/);
    // The other branch never noticed (it keeps up; stumbling once on a loaded machine is not lag).
    const other = summaryOf(cli.stdout()).blocks.find((b) => b.name === "Other")!;
    expect(KEEPING_UP).toContain(other.status);
    // A killed call is an error: the run says so in its exit code.
    expect(code, cli.stderr()).toBe(1);
  }, 40_000);
});
