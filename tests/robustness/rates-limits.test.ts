/**
 * Issue 14, item 10: status must not lie at extremes. `DesiredRate: 1e9` was accepted (one core at
 * 100 %, status idle, rate 0) and 200 kHz ran with ticks missed while the status read on time.
 * Now a ScheduledTimer is refused above MAX_TIMER_HZ (100 kHz) with a message naming the limit, and
 * so is a self-timed FilePlayer that would play rows faster; a timer that cannot keep up reads
 * lagging; and a `CatchUp: skip` timer that skipped ticks is not green (it reads lagging for as long
 * as the ticks it skipped span, at least 100 ms).
 */
import { writeFileSync } from "node:fs";
import { join } from "node:path";
import { describe, expect, test } from "vitest";
import { catalog } from "../../app/blocks/catalog";
import { MAX_TIMER_HZ } from "../../app/blocks/timing/scheduled-timer";
import type { Clock } from "../../app/engine/clock";
import { formatDiagnostic } from "../../app/engine/diagnostics";
import { loadPipeline } from "../../app/engine/pipeline/loader";
import { Runtime } from "../../app/engine/runtime/runtime";
import { noResources } from "../../app/engine/testing";
import { nodeResources } from "../../app/host/resources";
import { jsonLines, requireBuild, runCli, tempDir } from "../integration/helpers";
import { initDspForTests } from "../support/wasm";

initDspForTests();

/** Loads and instantiates `yaml` (real-time mode, a clock the test moves); its diagnostics. */
async function create(yaml: string, clock: Clock = { now: () => 1000 }, dir = "/tmp") {
  const loaded = loadPipeline(yaml, join(dir, "p.yaml"), catalog);
  if (!loaded.spec) return { runtime: undefined, errors: loaded.diagnostics.map(formatDiagnostic) };
  const r = await Runtime.create({
    spec: loaded.spec,
    catalog,
    clock,
    virtual: false,
    resources: dir === "/tmp" ? noResources : nodeResources(dir),
  });
  return {
    runtime: r.runtime,
    errors: r.diagnostics.filter((d) => d.severity === "error").map(formatDiagnostic),
  };
}

describe("rates the engine cannot pace are refused", () => {
  test("the limit is 100 kHz", () => {
    expect(MAX_TIMER_HZ).toBe(100_000);
  });

  test.each([1e9, 200_000, 100_001])(
    "ScheduledTimer at %d Hz: one error naming the limit",
    async (hz) => {
      const { runtime, errors } = await create(
        `Timer: { Type: ScheduledTimer, DesiredRate: ${hz} }\nSink: { Type: Sink, Inputs: [Timer] }\n`,
      );
      expect(runtime).toBeUndefined();
      expect(errors).toHaveLength(1);
      expect(errors[0]).toMatch(
        new RegExp(
          `^/tmp/p\\.yaml:1:1: error: block 'Timer' \\(ScheduledTimer\\): DesiredRate ${hz} Hz is above the fastest a timer is paced at, 100000 Hz`,
        ),
      );
    },
  );

  test("100 kHz is accepted", async () => {
    const { runtime, errors } = await create(
      "Timer: { Type: ScheduledTimer, DesiredRate: 100000 }\nSink: { Type: Sink, Inputs: [Timer] }\n",
    );
    expect(errors).toEqual([]);
    runtime!.dispose();
  });

  test("a FilePlayer playing rows faster than 100 kHz at its own timing is refused", async () => {
    const dir = tempDir("mosaic-rates-");
    const rows = ["time_s,a"];
    for (let i = 0; i < 100; i++) rows.push(`${i / 1000},${i}`);
    writeFileSync(join(dir, "rec.csv"), rows.join("\n") + "\n");
    const yaml = (speed: number) =>
      `Play: { Type: FilePlayer, Params: { File: rec.csv, Speed: ${speed} } }\nSink: { Type: Sink, Inputs: [Play] }\n`;
    const fast = await create(yaml(200), undefined, dir);
    expect(fast.errors).toHaveLength(1);
    expect(fast.errors[0]).toMatch(
      /error: block 'Play' \(FilePlayer\): at Speed 200 the rows of 'rec\.csv' \(1000 Hz\) would play at 200000 Hz, above the fastest the engine paces, 100000 Hz/,
    );
    const ok = await create(yaml(100), undefined, dir);
    expect(ok.errors).toEqual([]);
    ok.runtime!.dispose();
  });
});

describe("a timer that misses ticks is never green", () => {
  test("CatchUp: skip — a short stall (a few ticks) and a long one read lagging, then on time again", async () => {
    let now = 1000;
    const { runtime } = await create(
      "Timer: { Type: ScheduledTimer, DesiredRate: 100, Params: { CatchUp: skip } }\nSink: { Type: Sink, Inputs: [Timer] }\n",
      { now: () => now },
    );
    const rt = runtime!;
    rt.start();
    const status = () => rt.telemetry().blocks.find((b) => b.name === "Timer")!;
    const run = (until: number) => {
      // Steps at 500 Hz: every tick of the 100 Hz timer is taken on time.
      for (; now < until - 1e-9; now += 0.002) rt.step(now);
      now = until;
      rt.step(now);
    };
    run(1002);
    expect(status().status).toBe("ontime");
    now += 0.0505; // a stall of 5 periods: 4 ticks skipped, the 5th goes out
    rt.step(now);
    expect(status().timer!.missed).toBe(4);
    expect(status().status).toBe("lagging");
    run(now + 0.2);
    expect(status().status).toBe("ontime");
    now += 2; // a long stall, beyond the idle threshold
    rt.step(now);
    expect(status().status).toBe("lagging");
    run(now + 1.9);
    expect(status().status).toBe("lagging"); // as long as the ticks it skipped span
    run(now + 0.2);
    expect(status().status).toBe("ontime");
    rt.dispose();
  });

  test("100 kHz with a block that cannot keep up (mosaic run): lagging, never on time", () => {
    requireBuild();
    const dir = tempDir("mosaic-rates-");
    const file = join(dir, "slow.yaml");
    writeFileSync(
      file,
      [
        "Timer: { Type: ScheduledTimer, DesiredRate: 100000 }",
        "Slow: { Type: Busy, Inputs: [Timer], Params: { Milliseconds: 80 } }",
        "",
      ].join("\n"),
    );
    const r = runCli(["run", file, "--duration", "2.5", "--json", "--warmup", "0.5"]);
    const lines = jsonLines(r.stdout);
    const warmupEnd = lines.find((l) => l.type === "warmup-done")!.t as number;
    // Telemetry comes in groups of a quarter second, so reports from the warm-up can follow the
    // warmup-done line: a report belongs after the warm-up by its own time. The last telemetry
    // comes after the pipeline stopped (timers stopped: idle).
    const seen = lines
      .filter((l) => l.type === "telemetry" && (l.t as number) > warmupEnd)
      .slice(0, -1)
      .map(
        (l) =>
          (l.blocks as { name: string; status: string }[]).find((b) => b.name === "Timer")!.status,
      );
    expect(seen.length).toBeGreaterThan(5);
    expect(seen.filter((s) => s !== "lagging")).toEqual([]);
  });
});
