import { describe, expect, test } from "vitest";
import { z } from "zod";
import { defineBlock } from "./block";
import { runBlockContract, type CheckResult } from "./block-contract";
import { errorMessage } from "./diagnostics";
import { vectorShape } from "./frame";
import { LegacyParamsError } from "./pipeline/legacy";
import { TestGain, testCatalog } from "./test-blocks";
import { noResources } from "./testing";

const verdicts = (rs: CheckResult[]): Record<string, boolean> =>
  Object.fromEntries(rs.map((r) => [r.name, r.ok]));

/** Keeps only the first event of each frame: its output depends on how events are grouped. */
const FirstOnly = defineBlock({
  type: "FirstOnly",
  category: "Testing",
  summary: "first event of each frame",
  help: "Deliberately wrong for the contract test.",
  params: z.strictObject({}),
  inputs: { min: 1, max: 1 },
  create(ctx) {
    const out = ctx.output(vectorShape(2));
    return {
      process(f) {
        const o = out.frame(1);
        o.t[0] = f.t[0]!;
        o.v[0] = f.v[0]!;
        o.v[1] = f.v[1]!;
        out.emit(o);
      },
    };
  },
});

/** Allocates what its param says, unchecked: garbage params end in a RangeError. */
const Unchecked = defineBlock({
  type: "Unchecked",
  category: "Testing",
  summary: "an unchecked buffer size",
  help: "Deliberately wrong for the contract test.",
  params: z.strictObject({ Size: z.number().default(4).describe("buffer size") }),
  inputs: { min: 1, max: 1 },
  create(ctx, p) {
    const buf = new Float64Array(p.Size);
    const out = ctx.output(vectorShape(1));
    let sum = 0;
    return {
      process(f) {
        const o = out.frame(f.n);
        for (let i = 0; i < f.n; i++) {
          sum += f.v[i * f.stride]! + buf.length;
          o.t[i] = f.t[i]!;
          o.v[i] = sum;
        }
        out.emit(o);
      },
      // No reset: after reset the output does not repeat.
    };
  },
});

describe("the block contract as a program", () => {
  test("a block that keeps it passes every check", async () => {
    // Its positional form refuses an unknown operation with a LegacyParamsError, as the contract
    // asks (a plain Error there fails the garbage check, as one from create() does).
    const Gain = defineBlock({
      ...TestGain,
      type: "Gain2",
      legacyForm: "[gain:k]",
      legacyParams: (a: readonly string[]) => {
        try {
          return TestGain.legacyParams!(a);
        } catch (e) {
          throw e instanceof LegacyParamsError ? e : new LegacyParamsError(errorMessage(e));
        }
      },
    });
    const rs = await runBlockContract(Gain, { params: { Gain: 3 } }, noResources, testCatalog);
    expect(rs.filter((r) => !r.ok)).toEqual([]);
    expect(rs.map((r) => r.name)).toEqual([
      "docs",
      "defaults validate",
      "frame splitting",
      "reset repeats",
      "dispose twice",
      "garbage params",
    ]);
  });

  test("output that depends on the frames' sizes fails frame splitting, saying where", async () => {
    const rs = await runBlockContract(FirstOnly, {}, noResources, testCatalog);
    expect(verdicts(rs)["frame splitting"]).toBe(false);
    expect(rs.find((r) => r.name === "frame splitting")!.detail).toBe(
      "one frame of many events ≠ one event per frame: output 'out': 40 events vs 1",
    );
  });

  test("state that reset does not clear and an internal error on garbage params fail", async () => {
    const rs = await runBlockContract(Unchecked, {}, noResources, testCatalog);
    const v = verdicts(rs);
    expect(v["frame splitting"]).toBe(true);
    expect(v["reset repeats"]).toBe(false);
    expect(v["garbage params"]).toBe(false);
    expect(rs.find((r) => r.name === "garbage params")!.detail).toMatch(
      /\{"Size":-1\} → create: RangeError: Invalid typed array length: -1/,
    );
  });

  test("params the schema refuses fail 'defaults validate' with zod's words", async () => {
    const rs = await runBlockContract(TestGain, { params: {} }, noResources, testCatalog);
    expect(rs.find((r) => r.name === "defaults validate")!.detail).toMatch(
      /^params \{\} do not validate: Gain: /,
    );
  });
});
