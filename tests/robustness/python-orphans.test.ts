/**
 * Issue 14, item 2: no Python sidecar outlives `mosaic run`, whatever happens — the run ends by
 * its duration, by SIGINT, or the host is killed with SIGKILL — even while the user's function
 * hangs in `time.sleep(1e6)` or spins in a pure-Python loop. Every process the run starts
 * inherits a unique MOSAIC_TEST_MARK in its environment; after the host is gone, /proc must hold
 * none of them (within a short grace: the sidecar notices its host's end by itself).
 */
import { existsSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { afterEach, describe, expect, test } from "vitest";
import {
  commandLine,
  havePython,
  killMarked,
  markedPids,
  newMarker,
  noneLeft,
  requireBuild,
  startRun,
  until,
  workdir,
} from "./python/support";

let marker = "";
afterEach(() => killMarked(marker));

/** A pipeline whose Python block hangs (or spins) from its third call on. */
function hangingPipeline(dir: string, fn: "hang" | "spin"): string {
  const file = join(dir, "hang.yaml");
  writeFileSync(
    file,
    `
Timer: { Type: ScheduledTimer, DesiredRate: 50 }
Emg: { Type: EmgSimulator, Inputs: [Timer], Params: { Channels: 2 } }
Py:
  Type: Python
  Inputs: [Emg]
  Params: { Module: robust_funcs.py, Function: ${fn}, Init: init, Params: { flag: hanging.flag } }
Other: { Type: Function, Inputs: [Emg], Params: { Operation: abs } }
`,
  );
  return file;
}

const leftovers = (): string =>
  markedPids(marker)
    .map((p) => `${p}: ${commandLine(p)}`)
    .join("\n");

describe.skipIf(!havePython)("no sidecar outlives the host", () => {
  test("the run ends by its duration while a call hangs", async () => {
    requireBuild();
    const dir = workdir();
    marker = newMarker();
    const cli = startRun(
      [hangingPipeline(dir, "hang"), "--duration", "2.5", "--json"],
      dir,
      marker,
    );
    const { code } = await cli.exited;
    expect(code, cli.stderr()).not.toBeNull();
    expect(existsSync(join(dir, "hanging.flag")), cli.stderr()).toBe(true);
    expect(await noneLeft(marker, 3000), leftovers()).toBe(true);
  }, 30_000);

  test("SIGINT to the host while a call spins in pure Python", async () => {
    requireBuild();
    const dir = workdir();
    marker = newMarker();
    const cli = startRun([hangingPipeline(dir, "spin"), "--json"], dir, marker);
    await until(() => existsSync(join(dir, "hanging.flag")), 20_000, "the call to spin", cli);
    cli.child.kill("SIGINT");
    const { code } = await cli.exited;
    expect(code, cli.stderr()).not.toBeNull();
    expect(await noneLeft(marker, 3000), leftovers()).toBe(true);
  }, 30_000);

  test("SIGKILL of the host while a call hangs", async () => {
    requireBuild();
    const dir = workdir();
    marker = newMarker();
    const cli = startRun([hangingPipeline(dir, "hang"), "--json"], dir, marker);
    await until(() => existsSync(join(dir, "hanging.flag")), 20_000, "the call to hang", cli);
    expect(markedPids(marker).length).toBeGreaterThan(1);
    cli.child.kill("SIGKILL");
    const { signal } = await cli.exited;
    expect(signal).toBe("SIGKILL");
    expect(await noneLeft(marker, 3000), leftovers()).toBe(true);
  }, 30_000);
});
