// The steps of createFeatureBlock that features.test.ts does not reach: which param an error
// names, the window-size bound, the desired rate, empty frames and the instance of each form.
import { beforeAll, describe, expect, test } from "vitest";
import { BlockConfigError, Frame, matrixShape, vectorShape } from "../../engine";
import { BlockHarness } from "../../engine/testing";
import { vectors } from "../../../tests/support/blocks";
import { initDspForTests } from "../../../tests/support/wasm";
import { MAX_WINDOW_VALUES } from "./feature-block";
import { MeanAbsoluteValue } from "./mean-absolute-value";
import { Rms } from "./rms";

beforeAll(() => initDspForTests());

/** The error a creation throws (it must throw). */
async function creationError(p: Promise<unknown>): Promise<BlockConfigError> {
  try {
    await p;
  } catch (e) {
    return e as BlockConfigError;
  }
  throw new Error("expected the creation to fail");
}

describe("createFeatureBlock steps", () => {
  test("window matrices with Window or Hop: the error names the param given", async () => {
    const withHop = await creationError(
      BlockHarness.create(Rms, { Hop: 2 }, { inputs: [{ shape: matrixShape(4, 2) }] }),
    );
    expect(withHop).toBeInstanceOf(BlockConfigError);
    expect(withHop.message).toBe(
      "input 'in0' already carries windows [4, 2]; Window and Hop are only for a plain stream " +
        "[1, C], remove them",
    );
    expect(withHop.param).toBe("Hop");
    const both = await creationError(
      BlockHarness.create(Rms, { Window: 4, Hop: 2 }, { inputs: [{ shape: matrixShape(4, 2) }] }),
    );
    expect(both.param).toBe("Window");
  });

  test("a plain stream without Window, and a window holding too many values, name Window", async () => {
    const none = await creationError(
      BlockHarness.create(Rms, { Hop: 2 }, { inputs: [{ shape: vectorShape(2) }] }),
    );
    expect(none.param).toBe("Window");
    const big = await creationError(
      BlockHarness.create(
        Rms,
        { Window: 1 << 20 },
        { inputs: [{ shape: vectorShape(9), rate: 1000 }], desiredRate: 3 },
      ),
    );
    expect(big.message).toBe(
      `a window of ${1 << 20} samples × 9 channels holds more than ${MAX_WINDOW_VALUES} values; ` +
        "use a shorter Window",
    );
    expect(big.param).toBe("Window");
  });

  test("the desired rate: input rate / Hop, unless declared or the input rate is unknown", async () => {
    const opts = (rate: number, desiredRate?: number) => ({
      inputs: [{ shape: vectorShape(1), rate }],
      ...(desiredRate === undefined ? {} : { desiredRate }),
    });
    const h = await BlockHarness.create(Rms, { Window: 8 }, opts(1000));
    expect(h.desiredRate).toBe(125);
    const d = await BlockHarness.create(Rms, { Window: 8, Hop: 4 }, opts(1000, 7));
    expect(d.desiredRate).toBe(7);
    const z = await BlockHarness.create(Rms, { Window: 8, Hop: 4 }, opts(0));
    expect(z.desiredRate).toBe(0);
    const w = await BlockHarness.create(
      Rms,
      {},
      { inputs: [{ shape: matrixShape(8, 1), rate: 40 }] },
    );
    expect(w.desiredRate).toBe(40);
  });

  test("empty frames emit nothing; a stream output is stamped with its window's newest sample", async () => {
    const s = await BlockHarness.create(
      MeanAbsoluteValue,
      { Window: 2 },
      { inputs: [{ shape: vectorShape(1), rate: 10 }] },
    );
    s.start();
    s.push(new Frame(vectorShape(1), 4));
    s.push(vectors([0.1], [[-1]]));
    expect(s.output().t).toEqual([]);
    s.push(vectors([0.2, 0.3, 0.4], [[3], [-5], [7]]));
    expect(s.output()).toMatchObject({ t: [0.2, 0.4], v: [[2], [6]] });
    const w = await BlockHarness.create(
      MeanAbsoluteValue,
      {},
      { inputs: [{ shape: matrixShape(2, 1) }] },
    );
    w.start();
    w.push(new Frame(matrixShape(2, 1), 4));
    expect(w.output().t).toEqual([]);
    w.push(
      Frame.from(
        matrixShape(2, 1),
        [5, 6],
        [
          [1, -3],
          [4, 0],
        ],
      ),
    );
    expect(w.output()).toMatchObject({ t: [5, 6], v: [[2], [2]] });
  });

  test("the instance of each form: window matrices have no reset; both take live params", async () => {
    const w = await BlockHarness.create(Rms, {}, { inputs: [{ shape: matrixShape(2, 1) }] });
    expect(Object.keys(w.instance).sort()).toEqual(["dispose", "process", "setParam"]);
    const s = await BlockHarness.create(
      Rms,
      { Window: 2 },
      { inputs: [{ shape: vectorShape(1) }] },
    );
    expect(Object.keys(s.instance).sort()).toEqual(["dispose", "process", "reset", "setParam"]);
  });
});
