import { describe, expect, test } from "vitest";
import { vectorShape } from "../../engine";
import { BlockHarness, runVirtualPipeline } from "../../engine/testing";
import { convertLegacy, vectors } from "../../../tests/support/blocks";
import { catalog } from "../catalog";
import { Switch } from "./switch";

async function sw(params: object = {}, n = 2) {
  const h = await BlockHarness.create(Switch, params, {
    inputs: Array.from({ length: n }, (_, i) => ({ shape: vectorShape(2), rate: 100 * (i + 1) })),
  });
  h.start();
  return h;
}

const run = (h: BlockHarness, action: string, arg?: unknown) =>
  h.instance.actions![action]!.run(arg);

describe("Switch", () => {
  test("forwards only the active input; toggle and select change it; the rate follows", async () => {
    const h = await sw({}, 3);
    expect(h.text).toBe("forwarding in0");
    expect(h.desiredRate).toBe(100);
    h.push(vectors([0], [[1, 1]]), 0);
    h.push(vectors([0], [[2, 2]]), 1);
    expect(run(h, "toggle")).toBe("block forwards in1");
    expect(h.desiredRate).toBe(200);
    h.push(vectors([1], [[3, 3]]), 0);
    h.push(
      vectors(
        [1, 2],
        [
          [4, 4],
          [5, 5],
        ],
      ),
      1,
    );
    run(h, "select", "in2");
    h.push(vectors([3], [[6, 6]]), 2);
    run(h, "toggle"); // after the last: the first
    h.push(vectors([4], [[7, 7]]), 0);
    expect(h.output()).toMatchObject({
      t: [0, 1, 2, 3, 4],
      v: [
        [1, 1],
        [4, 4],
        [5, 5],
        [6, 6],
        [7, 7],
      ],
    });
    expect(run(h, "select", 1)).toBe("block forwards in1");
    expect(() => run(h, "select", "in9")).toThrow("'in9' is not an input of block (in0, in1, in2)");
    expect(() => run(h, "select", 3)).toThrow("a whole number from 0 to 2");
  });

  test("Active is live; reset returns to it", async () => {
    const h = await sw({ Active: 1 });
    expect(h.text).toBe("forwarding in1");
    h.instance.setParam!("Active", 0);
    run(h, "toggle");
    h.instance.reset!();
    expect(h.text).toBe("forwarding in0");
    expect(() => h.instance.setParam!("Active", 2)).toThrow("out of range");
  });

  test("an input written -Name is subscribed only while it is active", async () => {
    const h = await BlockHarness.create(
      Switch,
      { Active: 1 },
      {
        inputs: [
          { shape: vectorShape(1) },
          { shape: vectorShape(1), subscribed: false },
          { shape: vectorShape(1), subscribed: false },
        ],
      },
    );
    expect(h.subscribed).toEqual({ 1: true, 2: false });
    expect(h.text).toBe("forwarding in1");
    h.instance.actions!.select!.run(2);
    expect(h.subscribed).toEqual({ 1: false, 2: true });
    h.instance.actions!.select!.run(0);
    expect(h.subscribed).toEqual({ 1: false, 2: false });
  });

  test("inputs must share a shape; Active must name an input", async () => {
    await expect(
      BlockHarness.create(
        Switch,
        {},
        {
          inputs: [{ shape: vectorShape(2) }, { shape: vectorShape(3) }],
        },
      ),
    ).rejects.toThrow("input 'in1' has shape [1, 3], but 'in0' has [1, 2]");
    await expect(sw({ Active: 2 })).rejects.toThrow(
      "Active 2 is out of range: the Switch has 2 inputs",
    );
  });

  test("in a pipeline: switching by action at run time", async () => {
    const yaml =
      "T: { Type: ScheduledTimer, DesiredRate: 100 }\n" +
      "A: { Type: SinGenerator, Inputs: [T], Params: { Components: 2, Amplitude: 0 } }\n" +
      "B: { Type: SinGenerator, Inputs: [T], Params: { Components: 2, Amplitude: 5, Phase: 1.5707963267948966, Frequency: 0 } }\n" +
      "S: { Type: Switch, Inputs: [A, B] }\n";
    const r = await runVirtualPipeline(yaml, {
      catalog,
      duration: 0.05,
      record: ["S"],
      beforeRun: (rt) => rt.invoke("S", "toggle"),
    });
    const v = r.outputs.get("S")!.v;
    expect(v.length).toBeGreaterThan(3);
    for (const row of v) expect(row[0]).toBeCloseTo(5, 12);
  });

  test("legacy: no params", () => {
    expect(
      convertLegacy(
        "T: { Type: ScheduledTimer, DesiredRate: 10 }\n" +
          "A: { Type: SinGenerator, Inputs: [T] }\n" +
          "B: { Type: SinGenerator, Inputs: [T] }\n" +
          "S: { Type: Switch, Inputs: [A, -B], Params: [''] }\n",
        "S",
      ),
    ).toEqual({ Active: 0 });
  });
});
