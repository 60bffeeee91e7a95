// The steps of Switch's create that switch.test.ts does not reach: the messages of setParam and
// select, selecting by block name or a numeric string, the declared rate and empty frames.
import { describe, expect, test } from "vitest";
import { Frame, vectorShape } from "../../engine";
import { BlockHarness } from "../../engine/testing";
import { vectors } from "../../../tests/support/blocks";
import { Switch } from "./switch";

async function sw(opts: { desiredRate?: number } = {}) {
  const h = await BlockHarness.create(
    Switch,
    {},
    {
      inputs: [
        { shape: vectorShape(1), rate: 10 },
        { shape: vectorShape(1), rate: 20 },
        { shape: vectorShape(1), rate: 30 },
      ],
      ...opts,
    },
  );
  h.start();
  return h;
}

const select = (h: BlockHarness, arg: unknown) => h.instance.actions!.select!.run(arg);

describe("Switch steps", () => {
  test("setParam: other names are ignored, an out-of-range Active says the valid range", async () => {
    const h = await sw();
    h.instance.setParam!("DesiredRate", 2);
    expect(h.text).toBe("forwarding in0");
    expect(() => h.instance.setParam!("Active", 3)).toThrow(
      new Error("Active 3 is out of range (valid: 0–2)"),
    );
    expect(h.text).toBe("forwarding in0");
    h.instance.setParam!("Active", 2);
    expect([h.text, h.desiredRate]).toEqual(["forwarding in2", 30]);
    select(h, 1);
    h.instance.reset!();
    expect([h.text, h.desiredRate]).toEqual(["forwarding in2", 30]);
  });

  test("Active out of range at creation lists the inputs", async () => {
    await expect(
      BlockHarness.create(
        Switch,
        { Active: 3 },
        { inputs: [{ shape: vectorShape(1) }, { shape: vectorShape(1) }] },
      ),
    ).rejects.toThrow(
      "Active 3 is out of range: the Switch has 2 inputs ('in0', 'in1'; valid: 0–1)",
    );
  });

  test("select: a numeric string is a position; a near miss gets a suggestion", async () => {
    const h = await sw();
    expect(select(h, " 2 ")).toBe("block forwards in2");
    expect(select(h, "in1")).toBe("block forwards in1");
    expect(() => select(h, "in")).toThrow(
      new Error("'in' is not an input of block (in0, in1, in2); did you mean 'in0'?"),
    );
    expect(() => select(h, "zzzzzzzz")).toThrow(
      new Error("'zzzzzzzz' is not an input of block (in0, in1, in2)"),
    );
    expect(h.text).toBe("forwarding in1");
  });

  test("a declared rate is kept; empty frames and other inputs emit nothing", async () => {
    const h = await sw({ desiredRate: 5 });
    expect(h.desiredRate).toBe(5);
    select(h, 2);
    expect(h.desiredRate).toBe(5);
    h.push(new Frame(vectorShape(1), 2), 2);
    h.push(vectors([1], [[9]]), 0);
    expect(h.output().t).toEqual([]);
    h.push(vectors([2, 3], [[4], [5]]), 2);
    expect(h.output()).toMatchObject({ t: [2, 3], v: [[4], [5]] });
  });
});
