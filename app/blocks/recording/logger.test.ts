import { describe, expect, test } from "vitest";
import { catalog } from "../catalog";
import {
  loadPipeline,
  matrixShape,
  Runtime,
  runVirtual,
  vectorShape,
  VirtualClock,
} from "../../engine";
import { BlockHarness, noResources, runVirtualPipeline } from "../../engine/testing";
import { matrices, vectors } from "../../../tests/support/blocks";
import { Logger } from "./logger";

describe("Logger", () => {
  test("writes each input to <Folder>/<input>.txt in the Path line format", async () => {
    const run = await runVirtualPipeline(
      `
Timer: { Type: ScheduledTimer, DesiredRate: 4 }
Sin: { Type: SinGenerator, Inputs: [Timer], Params: { Components: 2, Frequency: 1, Amplitude: 2 } }
Log: { Type: Logger, Inputs: [Sin, Timer], Params: { Folder: out } }
`,
      { catalog, duration: 0.5, start: 1_700_000_000 },
    );
    expect([...run.logs.files.keys()].sort()).toEqual(["out/Sin.txt", "out/Timer.txt"]);
    const sin = run.logs.files.get("out/Sin.txt")!;
    expect(sin).toEqual([
      `1700000000.000000,${2 * Math.sin(0)},${2 * Math.sin(10)}`,
      `1700000000.250000,${2 * Math.sin(Math.PI / 2)},${2 * Math.sin(Math.PI / 2 + 10)}`,
      `1700000000.500000,${2 * Math.sin(Math.PI)},${2 * Math.sin(Math.PI + 10)}`,
    ]);
    expect(run.logs.files.get("out/Timer.txt")).toEqual([
      "1700000000.000000",
      "1700000000.250000",
      "1700000000.500000",
    ]);
    const log = run.telemetry.blocks.find((b) => b.name === "Log")!;
    // The status text is refreshed at most every 0.25 s of pipeline time.
    expect(log.text).toMatch(/^[1-6] lines? written to out\/$/);
  });

  test("matrices are written row by row; stop and start pause and resume; Recording is live", async () => {
    const h = await BlockHarness.create(
      Logger,
      {},
      {
        inputs: [{ shape: matrixShape(2, 2) }, { shape: vectorShape(1) }],
      },
    );
    h.start();
    h.push(
      matrices(
        [1],
        [
          [
            [1, 2],
            [3, 4],
          ],
        ],
      ),
      0,
    );
    expect(h.logs.files.get("recordings/in0.txt")).toEqual(["1.000000,1,2,3,4"]);
    expect(h.instance.actions!.stop!.run()).toBe("recording stopped (1 lines written)");
    expect(h.text).toBe("stopped (1 line written to recordings/)");
    h.push(vectors([2], [[5]]), 1);
    h.instance.actions!.start!.run();
    h.push(vectors([3], [[6]]), 1);
    h.instance.setParam!("Recording", false);
    h.push(vectors([4], [[7]]), 1);
    expect(h.logs.files.get("recordings/in1.txt")).toEqual(["3.000000,6"]);
    h.instance.setParam!("Recording", true);
    h.push(vectors([5], [[0.1]]), 1);
    expect(h.logs.files.get("recordings/in1.txt")).toEqual(["3.000000,6", "5.000000,0.1"]);
    h.instance.stop!();
    expect(h.text).toBe("3 lines written to recordings/");
  });

  test("says so when the runtime has no log sink (and records nothing, without failing)", async () => {
    const loaded = loadPipeline(
      "T: { Type: ScheduledTimer, DesiredRate: 4 }\nL: { Type: Logger, Inputs: [T] }\n",
      "test.yaml",
      catalog,
    );
    const clock = new VirtualClock(0);
    const { runtime } = await Runtime.create({
      spec: loaded.spec!,
      catalog,
      clock,
      virtual: true,
      resources: noResources,
      ignorePlacement: true,
    });
    const rt = runtime!;
    rt.start();
    runVirtual(rt, clock, 1);
    const l = rt.telemetry().blocks.find((b) => b.name === "L")!;
    expect(l.text).toBe("no log sink in this runtime: nothing is recorded");
    expect(l.errors).toBe(0);
    rt.dispose();
  });

  test("an input listed twice is an error", async () => {
    const r = await runVirtualPipeline(
      "T: { Type: ScheduledTimer, DesiredRate: 4 }\nL: { Type: Logger, Inputs: [T, T] }\n",
      { catalog, duration: 0 },
    ).catch((e: Error) => e.message);
    expect(r).toContain("input 'T' is listed twice");
  });
});
