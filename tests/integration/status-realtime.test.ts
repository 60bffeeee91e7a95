import { describe, expect, test } from "vitest";
import { writeFileSync } from "node:fs";
import { join } from "node:path";
import { jsonLines, KEEPING_UP, requireBuild, runCli, tempDir } from "./helpers";

// A deliberately slow block on its own worker: each call takes 70 ms against a 50 ms period.
// It keeps its rate by taking the events that queued meanwhile in one frame, so it is stumbling
// (magenta), not lagging. Its downstream consumer only wants the newest value (Queue: latest, as a
// device output would), so it gets one event per slow call and falls below 95 % of 20 Hz: lagging
// (red). The independent branch on the main worker stays on time (green).
const PIPELINE = `
Timer: { Type: ScheduledTimer, DesiredRate: 200 }
Emg: { Type: EmgSimulator, Inputs: [Timer], Params: { Channels: 4 } }
Rectify: { Type: Function, Inputs: [Emg], Params: { Operation: abs } }
Pace: { Type: DecimatorTimer, DesiredRate: 20, Inputs: [Timer] }
Feature: { Type: Resampler, Inputs: [Rectify, Pace] }
Heavy: { Type: Busy, Inputs: [Feature], Params: { Milliseconds: 70 }, Worker: heavy }
Control: { Type: Function, Inputs: [Heavy], Params: { Operation: abs }, Queue: { Policy: latest } }
`;

describe("status in real time", () => {
  test("slow block magenta, its downstream red, the independent branch green", () => {
    requireBuild();
    const dir = tempDir();
    const f = join(dir, "slow.yaml");
    writeFileSync(f, PIPELINE);
    const r = runCli(["run", f, "--duration", "6", "--json"], { timeoutMs: 40_000 });
    expect(r.code).toBe(0);
    const tel = jsonLines(r.stdout).filter((l) => l.type === "telemetry") as unknown as {
      blocks: { name: string; status: string; rate: number; worker: string; stumbling: boolean }[];
    }[];
    const last = tel.at(-1)!;
    const status = Object.fromEntries(last.blocks.map((b) => [b.name, b.status]));
    // The independent branch keeps up (one catch-up call may stumble on a loaded machine; the
    // shares below hold it to on time), Heavy is magenta, its downstream red.
    for (const name of ["Timer", "Emg", "Rectify", "Pace", "Feature"])
      expect(KEEPING_UP, name).toContain(status[name]);
    expect(status.Heavy).toBe("stumbling");
    expect(status.Control).toBe("lagging");
    expect(last.blocks.find((b) => b.name === "Heavy")!.worker).toBe("heavy");
    // Throughout the second half of the run, not just at the end.
    const late = tel.slice(Math.floor(tel.length / 2));
    const share = (name: string, s: string) =>
      late.filter((t) => t.blocks.find((b) => b.name === name)?.status === s).length / late.length;
    // The independent branch keeps up throughout (a catch-up call may stumble under load).
    expect(share("Rectify", "ontime") + share("Rectify", "stumbling")).toBeGreaterThan(0.95);
    expect(share("Rectify", "ontime")).toBeGreaterThan(0.8);
    // Heavy is never on time; mostly stumbling (a loaded machine that delays its worker makes
    // it lag now and then: 0.8 stumbling was seen under CI's load).
    const heavy = late.map((t) => t.blocks.find((b) => b.name === "Heavy")?.status);
    expect(heavy.filter((h) => h !== "stumbling" && h !== "lagging")).toEqual([]);
    expect(share("Heavy", "stumbling")).toBeGreaterThan(0.75);
    expect(share("Control", "lagging")).toBeGreaterThan(0.9);
  });
});
