import { describe, expect, test } from "vitest";
import { runVirtualPipeline } from "../../app/engine/testing";
import { catalog } from "../../app/blocks/catalog";

describe("engine smoke", () => {
  test("timer and decimator under the virtual clock", async () => {
    const run = await runVirtualPipeline(
      `
Timer: { Type: ScheduledTimer, DesiredRate: 200 }
Slow: { Type: DecimatorTimer, DesiredRate: 25, Inputs: [Timer] }
`,
      { catalog, duration: 1 },
    );
    const timer = run.outputs.get("Timer")!;
    const slow = run.outputs.get("Slow")!;
    expect(timer.t.length).toBe(201);
    expect(timer.t[1]).toBeCloseTo(0.005, 12);
    expect(slow.t.length).toBe(26);
    expect(slow.t[1]).toBeCloseTo(0.04, 12);
    const b = run.telemetry.blocks.find((x) => x.name === "Slow")!;
    expect(b.status).toBe("ontime");
    expect(b.rate).toBeCloseTo(25, 6);
  });
});
