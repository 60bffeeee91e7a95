/**
 * The Python-backed blocks with a fake sidecar that records what the blocks load and send (the
 * real sidecar runs in tests/integration/python-blocks.test.ts, the modules' maths in
 * native-bridges/python/tests/test_blocks.py).
 */
import { describe, expect, test } from "vitest";
import {
  createCatalog,
  Frame,
  loadPipeline,
  matrixShape,
  vectorShape,
  type IoBridges,
  type PythonLoadOptions,
} from "../../engine";
import { BlockHarness } from "../../engine/testing";
import { memoryResources } from "../../../tests/support/fs-resources";
import { PythonNetFiltUC } from "../signal/python-net-filt-uc";
import { INmf } from "./inmf";
import { PythonNetLearning } from "./python-net-learning";
import { SimplePyTorch } from "./simple-pytorch";

/** A sidecar answering every call with `answer(values)`; loads and calls are recorded. */
function fakePython(answer: (v: Float64Array) => number[]) {
  const loads: PythonLoadOptions[] = [];
  const calls: number[][] = [];
  let resets = 0;
  const io: IoBridges = {
    python: {
      load: (o) => {
        loads.push(o);
        let id = 0;
        const shape = o.outputShape ?? o.inputShape;
        return Promise.resolve({
          outputShape: shape,
          pid: 1,
          version: "fake",
          ready: true,
          call: (values) => {
            calls.push(Array.from(values));
            o.onResult(++id, Float64Array.from(answer(values)), 1);
            return id;
          },
          reset: () => resets++,
          close: () => {},
        });
      },
    },
  };
  return { io, loads, calls, resets: () => resets };
}

describe("Python-backed blocks", () => {
  test("PythonNetFiltUC: MOSAIC's [type, n, f, script, fs] and what the sidecar gets", async () => {
    const r = loadPipeline(
      "F: { Type: PythonNetFiltUC, Inputs: [F], Params: [ 1, 2 , 3, '..\\\\x.py', 200] }\n",
      "p.yaml",
      createCatalog([PythonNetFiltUC]),
    );
    expect(r.spec!.blocks[0]!.params).toEqual({
      Filter: "notch",
      Order: 2,
      Q: 2,
      Frequency: 3,
      SampleRate: 200,
      Initial: "step",
    });
    const py = fakePython((v) => Array.from(v));
    await BlockHarness.create(PythonNetFiltUC, r.spec!.blocks[0]!.params, {
      inputs: [{ shape: vectorShape(10), rate: 200 }],
      io: py.io,
    });
    expect(py.loads[0]).toMatchObject({
      module: "mosaic_blocks.filt_uc",
      function: "step",
      init: "init",
      params: { kind: "notch", q: 2, frequency: 3, fs: 200, initial: "step" },
      outputShape: { rows: 1, cols: 10 },
    });
    await expect(
      BlockHarness.create(
        PythonNetFiltUC,
        { Frequency: 5 },
        { inputs: [{ shape: matrixShape(10, 2), rate: 20 }], io: py.io },
      ),
    ).rejects.toThrow(/windows of 10 samples.*give SampleRate/);
    await expect(
      BlockHarness.create(
        PythonNetFiltUC,
        { Frequency: 150, SampleRate: 200 },
        { inputs: [{ shape: vectorShape(1) }], io: py.io },
      ),
    ).rejects.toThrow(/not below the Nyquist frequency \(100 Hz/);
  });

  test("iNMF with MOSAIC's [updates, samples]: flagged rows in, only the samples' activations out", async () => {
    // The fake returns [emit?, h…]: emit when a row is flagged 0 (a sample), h = its first value.
    const py = fakePython((v) => {
      const W = 4;
      let emit = 0;
      let h = 0;
      for (let r = 0; r < v.length / W; r++) {
        if (v[r * W] === 0) {
          emit = 1;
          h = v[r * W + 1]!;
        }
      }
      return [emit, h, 0, 0];
    });
    const h = await BlockHarness.create(
      INmf,
      { Synergies: 2, Outputs: 3 },
      { inputs: [{ shape: matrixShape(2, 3) }, { shape: vectorShape(3) }], io: py.io },
    );
    h.start();
    expect(py.loads[0]).toMatchObject({
      module: "mosaic_blocks.inmf",
      inputShape: { rows: 2, cols: 4 },
      outputShape: { rows: 1, cols: 4 },
      params: { n_synergies: 2, outputs: 3, forgetting: 0.85 },
    });
    h.push(Frame.from(matrixShape(2, 3), [1], [[1, 2, 3, 4, 5, 6]]), 0);
    h.push(Frame.from(vectorShape(3), [2], [[7, 8, 9]]), 1);
    expect(py.calls).toEqual([
      [1, 1, 2, 3, 1, 4, 5, 6],
      [0, 7, 8, 9, NaN, NaN, NaN, NaN],
    ]);
    expect(h.output().v).toEqual([[7, 0, 0]]);
    expect(h.output().t).toEqual([2]);
    // Update off: batches are not sent.
    h.instance.setParam?.("Update", false);
    h.push(Frame.from(matrixShape(2, 3), [3], [[1, 2, 3, 4, 5, 6]]), 0);
    expect(py.calls).toHaveLength(2);
  });

  test("iNMF's positional form: the original's ten numbers", () => {
    const r = loadPipeline(
      "N: { Type: iNMF, Inputs: [N], Params: [ 12, 0.9, 3, 8, 100, 0, 0, 0.0001, 5, 50 ] }\n",
      "p.yaml",
      createCatalog([INmf]),
    );
    expect(r.spec!.blocks[0]!.params).toMatchObject({
      Outputs: 12,
      Forgetting: 0.9,
      Synergies: 3,
      Features: 8,
      WIters: 5,
      HIters: 50,
    });
    const bad = loadPipeline(
      "N: { Type: iNMF, Inputs: [N], Params: [ 12, 0.9, 3, 8, 100, 0.5 ] }\n",
      "p.yaml",
      createCatalog([INmf]),
    );
    expect(bad.diagnostics.find((d) => d.severity === "error")?.message).toMatch(
      /synergyReg 0.5: regularisation is not supported/,
    );
  });

  test("PythonNetLearning: train writes the Buffer's rows for the sidecar and re-initialises it", async () => {
    const py = fakePython(() => [0, 0]);
    const files: Record<string, string> = {};
    const h = await BlockHarness.create(
      PythonNetLearning,
      { Buffer: "store" },
      {
        inputs: [{ shape: vectorShape(3), rate: 25 }],
        io: py.io,
        resources: memoryResources(files),
      },
    );
    expect(py.loads[0]).toMatchObject({
      module: "mosaic_blocks.learning",
      function: "apply",
      params: {
        method: "pca",
        n_components: 2,
        targets: 1,
        features: 3,
        training: "block.training.csv",
      },
      outputShape: { rows: 1, cols: 2 },
    });
    // No Buffer named 'store' in this harness: the action says so.
    expect(() => h.instance.actions!.train!.run()).toThrow(/there is no Buffer 'store'/);
  });

  test("SimplePyTorch loads its module with the model's path", async () => {
    const py = fakePython(() => [0.5]);
    const h = await BlockHarness.create(
      SimplePyTorch,
      { Model: "net.pt" },
      { inputs: [{ shape: vectorShape(5) }], io: py.io },
    );
    h.start();
    expect(py.loads[0]).toMatchObject({
      module: "mosaic_blocks.torch_model",
      function: "predict",
      params: { model: "net.pt" },
      outputShape: { rows: 1, cols: 1 },
    });
    h.push(Frame.from(vectorShape(5), [1], [[1, 2, 3, 4, 5]]));
    expect(h.output().v).toEqual([[0.5]]);
  });
});
