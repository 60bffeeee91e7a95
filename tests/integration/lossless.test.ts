import { spawn, type ChildProcess } from "node:child_process";
import { readFileSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { afterEach, describe, expect, test } from "vitest";
import { jsonLines, requireBuild, runCli, tempDir } from "./helpers";

// The acquisition part of the paper's Delsys pipeline (32 channels at 1926 Hz) with its output
// logged, run while a neighbour process keeps one of the machine's cores busy. A lost tick would
// be a hole in the recording: every tick index must be in the log, in order, exactly once.
const RATE = 1926;
const PIPELINE = `
Timer: { Type: ScheduledTimer, DesiredRate: ${RATE} }
Delsys:
  Type: EmgSimulator
  Inputs: [Timer]
  Params: { Channels: 32, Seed: 2 }
  Path: out/
Amplification: { Type: Function, Inputs: [Delsys], Params: { Operation: multiply, Value: 5 } }
Rectification: { Type: Function, Inputs: [Amplification], Params: { Operation: abs } }
LowPass:
  Type: Filter
  Inputs: [Rectification]
  Params:
    Numerator: [1.0593673840736209e-05, 2.1187347681472417e-05, 1.0593673840736209e-05]
    Denominator: [1, -1.9907728938050666, 0.9908152685004296]
Decimator: { Type: DecimatorTimer, DesiredRate: 25, Inputs: [Timer] }
Resampler: { Type: Resampler, Inputs: [LowPass, Decimator] }
`;

let burner: ChildProcess | undefined;
afterEach(() => {
  burner?.kill("SIGKILL");
  burner = undefined;
});

describe("lossless acquisition", () => {
  test("with a CPU-burning neighbour, the logged acquisition output holds every tick, no gap", () => {
    requireBuild();
    const dir = tempDir();
    const file = join(dir, "delsys.yaml");
    writeFileSync(file, PIPELINE);
    burner = spawn(process.execPath, ["-e", "for (;;) {}"], { stdio: "ignore" });
    const r = runCli(["run", file, "--duration", "4", "--json"], { timeoutMs: 60_000 });
    expect(r.code).toBe(0);

    const lines = readFileSync(join(dir, "out", "Delsys.txt"), "utf8")
      .trimEnd()
      .split("\n");
    const times = lines.map((l) => Number(l.slice(0, l.indexOf(","))));
    expect(lines[0]!.split(",")).toHaveLength(33);
    // Timestamps are the ticks' deadlines, base + k / rate, logged with microseconds.
    const base = times[0]!;
    const ks = times.map((t) => Math.round((t - base) * RATE));
    times.forEach((t, i) => expect(Math.abs(t - (base + ks[i]! / RATE))).toBeLessThan(2e-6));
    const gaps = ks.filter((k, i) => i > 0 && k !== ks[i - 1]! + 1);
    expect(gaps).toEqual([]);
    expect(ks.at(-1)).toBe(lines.length - 1);
    expect(lines.length).toBeGreaterThan(RATE * 3.5);

    // The engine agrees: no tick missed, nothing dropped, the Resampler at the exact rate.
    const summary = jsonLines(r.stdout).find((l) => l.type === "summary") as unknown as {
      blocks: { name: string; events: number; timer?: { fired: number; missed: number } }[];
      edges: { dropped: number }[];
      logs: string[];
    };
    const timer = summary.blocks.find((b) => b.name === "Timer")!.timer!;
    expect(timer.missed).toBe(0);
    expect(timer.fired).toBe(lines.length);
    expect(summary.edges.reduce((s, e) => s + e.dropped, 0)).toBe(0);
    expect(summary.blocks.find((b) => b.name === "Delsys")!.events).toBe(lines.length);
  }, 90_000);
});
