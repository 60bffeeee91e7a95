/**
 * PythonNetLearning with a fake sidecar and a Buffer published by name: the Components check,
 * the train action (the CSV written for the sidecar, then its re-initialisation) and AutoTrain.
 */
import { describe, expect, test } from "vitest";
import { vectorShape, type BlockContext, type IoBridges, type Resources } from "../../engine";
import { BlockHarness } from "../../engine/testing";
import { memoryResources } from "../../../tests/support/fs-resources";
import type { BufferRows } from "../flow/buffer";
import { publish } from "../shared/named";
import { PythonNetLearning } from "./python-net-learning";

/** A sidecar that answers zeros and counts its re-initialisations and closes. */
function fakePython() {
  const counts = { resets: 0, closes: 0 };
  const io: IoBridges = {
    python: {
      load: (o) =>
        Promise.resolve({
          outputShape: o.outputShape ?? o.inputShape,
          pid: 1,
          version: "fake",
          ready: true,
          call: () => 1,
          reset: () => counts.resets++,
          close: () => counts.closes++,
        }),
    },
  };
  return { io, counts };
}

/** A Buffer named `name` holding `rows` (each [target…, data…]); `close()` ends a cluster. */
function fakeBuffer(resources: Resources, name: string, T: number, D: number, rows: number[][]) {
  const listeners: (() => void)[] = [];
  let unlistened = 0;
  const buffer: BufferRows = {
    targetWidth: T,
    dataWidth: D,
    rows: () => rows.length,
    values: () => Float64Array.from(rows.flat()),
    onClusterClosed(fn) {
      listeners.push(fn);
      return () => unlistened++;
    },
  };
  publish({ resources, name } as BlockContext, "Buffer", buffer);
  return {
    close: () => listeners.forEach((fn) => fn()),
    listeners: () => listeners.length,
    unlistened: () => unlistened,
  };
}

const flush = () => new Promise((r) => setTimeout(r, 0));

async function harness(params: Record<string, unknown>, files: Record<string, string>) {
  const py = fakePython();
  const resources = memoryResources(files);
  const h = await BlockHarness.create(PythonNetLearning, params, {
    inputs: [{ shape: vectorShape(2), rate: 25 }],
    io: py.io,
    resources,
  });
  return { h, py, resources };
}

describe("PythonNetLearning", () => {
  test("more Components than input values is a config error on Components", async () => {
    await expect(harness({ Buffer: "store", Components: 3 }, {})).rejects.toMatchObject({
      name: "BlockConfigError",
      param: "Components",
      message: "Components 3 is more than the 2 values of input 'in0'",
    });
  });

  test("train writes the Buffer's rows as CSV, then re-initialises the sidecar", async () => {
    const files: Record<string, string> = {};
    const { h, py, resources } = await harness({ Buffer: "store", TrainingFile: "t.csv" }, files);
    const rows = [
      [1, 0.5, -2],
      [2, 3, 4.25],
    ];
    fakeBuffer(resources, "store", 1, 2, rows);
    expect(h.instance.actions!.train!.run()).toBe("training pca on 2 rows of 'store'");
    expect(py.counts.resets).toBe(0);
    await flush();
    expect(files["t.csv"]).toBe("1,0.5,-2\n2,3,4.25\n");
    expect(py.counts.resets).toBe(1);
    rows.length = 0;
    expect(h.instance.actions!.train!.run()).toBe(
      "the Buffer 'store' is empty: nothing to train on",
    );
  });

  test("train refuses a Buffer of other widths", async () => {
    const { h, resources } = await harness({ Buffer: "store" }, {});
    fakeBuffer(resources, "store", 2, 2, [[1, 2, 3, 4]]);
    expect(() => h.instance.actions!.train!.run()).toThrow(
      "the Buffer 'store' stores targets of 2 and data of 2 values; this block reads 2 values and Targets is 1",
    );
  });

  test("no re-initialisation when disposed before the file is written", async () => {
    const files: Record<string, string> = {};
    const { h, py, resources } = await harness({ Buffer: "store" }, files);
    fakeBuffer(resources, "store", 1, 2, [[1, 2, 3]]);
    h.instance.actions!.train!.run();
    h.instance.dispose?.();
    await flush();
    expect(files["block.training.csv"]).toBe("1,2,3\n");
    expect(py.counts.resets).toBe(0);
    expect(py.counts.closes).toBe(1);
  });

  test("AutoTrain: a missing Buffer is said at start", async () => {
    const { h } = await harness({ Buffer: "nope", AutoTrain: true }, {});
    h.start();
    expect(h.warnings).toEqual([
      "Buffer 'nope': there is no Buffer 'nope' in this pipeline on this worker (a block on " +
        "another Worker cannot be read by name); the model cannot be trained from it",
    ]);
  });

  test("AutoTrain: a closed cluster trains at the next event; listened once, unlistened at dispose", async () => {
    const files: Record<string, string> = {};
    const { h, py, resources } = await harness({ Buffer: "store", AutoTrain: true }, files);
    const b = fakeBuffer(resources, "store", 1, 2, [[0, 1, 2]]);
    h.start();
    h.start();
    expect(b.listeners()).toBe(1);
    b.close();
    expect(files["block.training.csv"]).toBeUndefined();
    expect(h.fireOneShot()).toBe(true);
    await flush();
    expect(files["block.training.csv"]).toBe("0,1,2\n");
    expect(py.counts.resets).toBe(1);
    h.instance.dispose?.();
    expect(b.unlistened()).toBe(1);
  });

  test("AutoTrain: a training that fails is a warning", async () => {
    const { h, resources } = await harness({ Buffer: "store", AutoTrain: true }, {});
    const b = fakeBuffer(resources, "store", 3, 2, []);
    h.start();
    b.close();
    h.fireOneShot();
    expect(h.warnings).toEqual([
      "the Buffer 'store' stores targets of 3 and data of 2 values; this block reads 2 values and Targets is 1",
    ]);
  });
});
