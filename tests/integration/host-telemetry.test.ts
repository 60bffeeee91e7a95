/**
 * The host's telemetry: workers send their blocks and edges as JSON text; the host prints the
 * merged line without parsing it (mosaic run --json) and parses it only for whoever wants objects.
 * Both must say the same thing, across workers.
 */
import { writeFileSync } from "node:fs";
import { join } from "node:path";
import { expect, test } from "vitest";
import { Host } from "../../app/host/host";
import type { Telemetry } from "../../app/engine/runtime/runtime";
import { requireBuild, tempDir } from "./helpers";

test("the JSON line equals the merged objects, with blocks on two workers", async () => {
  requireBuild();
  const dir = tempDir();
  const file = join(dir, "two.yaml");
  writeFileSync(
    file,
    "Timer: { Type: ScheduledTimer, DesiredRate: 200 }\n" +
      "Emg: { Type: EmgSimulator, Inputs: [Timer], Params: { Channels: 2 } }\n" +
      "Abs: { Type: Function, Inputs: [Emg], Params: { Operation: abs }, Worker: other }\n",
  );
  const pairs: { line: string; objects: Telemetry }[] = [];
  let objects: Telemetry | undefined;
  const { host, diagnostics } = await Host.load(
    file,
    { telemetryHz: 20 },
    {
      telemetry: (t) => (objects = t),
      telemetryLine: (line) => pairs.push({ line, objects: objects! }),
    },
  );
  expect(diagnostics.filter((d) => d.severity === "error")).toEqual([]);
  host!.start();
  await new Promise((r) => setTimeout(r, 600));
  await host!.stop();
  expect(pairs.length).toBeGreaterThan(5);
  for (const { line, objects: t } of pairs) {
    expect(JSON.parse(line)).toEqual({ type: "telemetry", ...t });
  }
  const last = JSON.parse(pairs.at(-1)!.line) as Telemetry;
  expect(last.blocks.map((b) => `${b.name}@${b.worker}`).sort()).toEqual([
    "Abs@other",
    "Emg@main",
    "Timer@main",
  ]);
  expect(last.edges.length).toBe(2);
}, 30_000);

test("reports travel in groups; what waits is sent before the worker stops, in order", async () => {
  requireBuild();
  const dir = tempDir();
  const file = join(dir, "one.yaml");
  writeFileSync(
    file,
    "Timer: { Type: ScheduledTimer, DesiredRate: 200 }\n" +
      "Emg: { Type: EmgSimulator, Inputs: [Timer], Params: { Channels: 2 } }\n",
  );
  const times: number[] = [];
  // Groups of 10 s at 20 Hz (200 reports): nothing is sent while the pipeline runs for 1 s.
  const { host } = await Host.load(
    file,
    { telemetryHz: 20, telemetryGroupS: 10 },
    { telemetryLine: (line) => times.push((JSON.parse(line) as Telemetry).t) },
  );
  host!.start();
  await new Promise((r) => setTimeout(r, 1000));
  expect(times).toEqual([]);
  await host!.stop();
  // Every report of that second arrives at the stop, oldest first, each with its own time.
  expect(times.length).toBeGreaterThanOrEqual(10);
  expect(times.length).toBeLessThanOrEqual(25);
  for (let i = 1; i < times.length; i++) expect(times[i]!).toBeGreaterThan(times[i - 1]!);
}, 30_000);
