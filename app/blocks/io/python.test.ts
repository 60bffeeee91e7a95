import { describe, expect, test } from "vitest";
import {
  BlockConfigError,
  Frame,
  matrixShape,
  vectorShape,
  type PythonBridge,
  type PythonLoadOptions,
  type PythonSidecar,
} from "../../engine";
import { BlockHarness } from "../../engine/testing";
import { Python } from "./python";

/** A sidecar whose calls stay outstanding until the test answers them. */
function manualBridge(opts: { fail?: Error & { kind?: string } } = {}) {
  const calls: { id: number; values: number[] }[] = [];
  let o!: PythonLoadOptions;
  let next = 1;
  let ready = true;
  let resets = 0;
  let closed = 0;
  const bridge: PythonBridge = {
    load: (options) => {
      o = options;
      if (opts.fail) return Promise.reject(opts.fail);
      const sc: PythonSidecar = {
        outputShape: options.outputShape ?? options.inputShape,
        pid: 42,
        version: "fake",
        get ready() {
          return ready;
        },
        call: (values) => {
          if (!ready) return -1;
          calls.push({ id: next, values: [...values] });
          return next++;
        },
        reset: () => void resets++,
        close: () => void closed++,
      };
      return Promise.resolve(sc);
    },
  };
  return {
    bridge,
    calls,
    get options() {
      return o;
    },
    get resets() {
      return resets;
    },
    get closed() {
      return closed;
    },
    /** Answers the oldest outstanding call with `values` (default: its input + 1). */
    answer(values?: number[], us = 100): void {
      const c = calls.shift()!;
      o.onResult(c.id, new Float64Array(values ?? c.values.map((v) => v + 1)), us);
    },
    fail(message: string): void {
      const c = calls.shift()!;
      o.onError(c.id, { message, traceback: "Traceback…\nValueError: bad", kind: "call" });
    },
    crash(): void {
      ready = false;
      for (const c of calls.splice(0)) {
        o.onError(c.id, { message: "the Python process died", traceback: "", kind: "crash" });
      }
      o.onStatus(
        "restarting",
        "the Python process (pid 42) killed by SIGKILL; restarting in 0.5 s",
      );
    },
    restarted(): void {
      ready = true;
      o.onStatus("ready", "restarted (pid 43)");
    },
    restartFailed(): void {
      o.onStatus("restarting", "restart failed: no python; retrying in 1 s");
    },
    /** The bridge's report of the oldest call still running after `ms`. */
    late(ms: number): void {
      o.onLate?.(calls[0]!.id, ms);
    },
  };
}

const ev = (t: number, ...v: number[]): Frame => Frame.from(vectorShape(v.length), [t], [v]);

async function harness(params: object, b = manualBridge(), rate = 100) {
  const h = await BlockHarness.create(
    Python,
    { Module: "m.py", Function: "f", ...params },
    {
      inputs: [{ shape: vectorShape(2), rate }],
      io: { python: b.bridge },
      virtual: false,
      resources: {
        resolve: (p) => `/pipelines/${p}`,
        readText: () => Promise.reject(new Error("no")),
        writeText: () => Promise.resolve(),
      },
    },
  );
  h.start();
  return { h, b };
}

describe("Python block (fake sidecar)", () => {
  test("load options: file modules resolved against the pipeline, names as given", async () => {
    const { b } = await harness({ Init: "init", Params: { k: [1, 2] } });
    expect(b.options).toMatchObject({
      module: "/pipelines/m.py",
      function: "f",
      init: "init",
      params: { k: [1, 2] },
      inputShape: { rows: 1, cols: 2 },
      cwd: "/pipelines/.",
    });
    const { b: b2 } = await harness({ Module: "sklearn.decomposition" });
    expect(b2.options.module).toBe("sklearn.decomposition");
  });

  test("confined (a pipeline from a serve or desktop client): installed modules by name are refused", async () => {
    const confined = (Module: string) =>
      BlockHarness.create(
        Python,
        { Module, Function: "system", Init: "system", Params: { cmd: "touch /tmp/x" } },
        {
          inputs: [{ shape: vectorShape(2), rate: 100 }],
          io: { python: manualBridge().bridge },
          virtual: false,
          resources: {
            resolve: (p) => `/pipelines/${p}`,
            readText: () => Promise.reject(new Error("no")),
            writeText: () => Promise.resolve(),
            confined: true,
          },
        },
      );
    await expect(confined("os")).rejects.toThrow(
      /Module 'os' is an installed module name; a pipeline loaded by a client of mosaic serve or the desktop app may run only Python files in its own folder/,
    );
    // Its own files, and the sidecar's shipped modules (the Python-backed blocks), still load.
    await expect(confined("model.py")).resolves.toBeDefined();
    await expect(confined("mosaic_blocks.learning")).resolves.toBeDefined();
  });

  test("results are emitted with the input's timestamp; one call in flight, the newest input waits", async () => {
    const { h, b } = await harness({});
    h.push(ev(1, 1, 1));
    h.push(ev(2, 2, 2)); // waits
    h.push(ev(3, 3, 3)); // replaces 2
    expect(b.calls.map((c) => c.values)).toEqual([[1, 1]]);
    b.answer();
    expect(h.output().t).toEqual([1]);
    expect(h.output().v).toEqual([[2, 2]]);
    expect(b.calls.map((c) => c.values)).toEqual([[3, 3]]); // the waiting one went out
    b.answer();
    expect(h.output().t).toEqual([1, 3]);
    expect(h.text).toMatch(/pid 42 · p50 .* · 1 skipped/);
  });

  test("MaxInFlight sends several calls before an answer; a frame of events is split into calls", async () => {
    const { h, b } = await harness({ MaxInFlight: 3 });
    h.push(
      Frame.from(
        vectorShape(2),
        [1, 2, 3, 4],
        [
          [1, 0],
          [2, 0],
          [3, 0],
          [4, 0],
        ],
      ),
    );
    expect(b.calls.map((c) => c.values[0])).toEqual([1, 2, 3]);
    b.answer();
    b.answer();
    b.answer();
    b.answer();
    expect(h.output().t).toEqual([1, 2, 3, 4]);
  });

  test("call time reported to the runtime with the budget; over-budget calls counted", async () => {
    const { h, b } = await harness({ Budget: 0.001 });
    h.push(ev(1, 1, 1));
    const t0 = performance.now();
    while (performance.now() - t0 < 2);
    b.answer();
    expect(h.computeReports).toHaveLength(1);
    expect(h.computeReports[0]!.ms).toBeGreaterThanOrEqual(2);
    expect(h.computeReports[0]!.budgetMs).toBe(0.001);
    expect(h.text).toMatch(/1 over budget \(0\.00 ms\)/);
    // Default budget: one period of the desired rate.
    const { h: h2, b: b2 } = await harness({}, manualBridge(), 25);
    h2.push(ev(1, 1, 1));
    b2.answer();
    expect(h2.computeReports[0]!.budgetMs).toBe(40);
    expect(h2.text).toMatch(/0 over budget \(40\.0 ms\)/);
  });

  test("OnError hold emits the last good output again; skip emits nothing; both keep running", async () => {
    const { h, b } = await harness({});
    h.push(ev(1, 1, 1));
    b.fail("ValueError: bad (before any good output)");
    expect(h.output().t).toEqual([]); // nothing good to hold yet
    h.push(ev(2, 5, 5));
    b.answer();
    h.push(ev(3, 7, 7));
    b.fail("ValueError: bad");
    expect(h.output().t).toEqual([2, 3]);
    expect(h.output().v).toEqual([
      [6, 6],
      [6, 6],
    ]);
    // Errors, counted by the runtime like exceptions in `process`, with their traceback.
    expect(h.errors).toHaveLength(2);
    expect(h.errors[0]).toMatch(/ValueError: bad \(before any good output\)\nTraceback…/);
    expect(h.warnings).toEqual([]);
    expect(h.text).toMatch(/2 errors \(last: ValueError: bad\)/);
    const { h: s, b: sb } = await harness({ OnError: "skip" });
    s.push(ev(1, 1, 1));
    sb.answer();
    s.push(ev(2, 1, 1));
    sb.fail("boom");
    s.push(ev(3, 1, 1));
    sb.answer();
    expect(s.output().t).toEqual([1, 3]);
  });

  test("a crash is reported, inputs wait during the restart, and calls resume after it", async () => {
    const { h, b } = await harness({});
    h.push(ev(1, 1, 1));
    b.answer();
    h.push(ev(2, 2, 2));
    b.crash();
    // One error per crash (not per call it lost).
    expect(h.errors).toHaveLength(1);
    expect(h.errors[0]).toMatch(/killed by SIGKILL; restarting in 0\.5 s/);
    expect(h.text).toMatch(/restarting in 0\.5 s · 1 restart/);
    expect(h.output().t).toEqual([1, 2]); // the lost call held the last good output
    h.push(ev(3, 3, 3)); // sidecar down: waits
    expect(b.calls).toEqual([]);
    b.restarted();
    expect(b.calls.map((c) => c.values)).toEqual([[3, 3]]);
    b.answer();
    expect(h.output().t).toEqual([1, 2, 3]);
    expect(h.text).toMatch(/^pid 42 .* · 1 restart$/);
  });

  test("results after stop are dropped; reset clears the held output and re-inits; dispose closes", async () => {
    const { h, b } = await harness({});
    h.push(ev(1, 1, 1));
    h.instance.stop?.();
    b.answer();
    expect(h.output().t).toEqual([]);
    h.instance.reset?.();
    expect(b.resets).toBe(1);
    h.instance.dispose?.();
    expect(b.closed).toBe(1);
  });

  test("load errors become positioned config errors naming the right param", async () => {
    const cases: [string, string][] = [
      ["missing-module", "Module"],
      ["syntax", "Module"],
      ["missing-function", "Function"],
      ["init", "Init"],
      ["shape", "Function"],
    ];
    for (const [kind, param] of cases) {
      const err = Object.assign(new Error(`problem of kind ${kind}`), { kind });
      const p = harness({ Init: "init" }, manualBridge({ fail: err }));
      await expect(p).rejects.toBeInstanceOf(BlockConfigError);
      await expect(p).rejects.toMatchObject({
        message: `Python: problem of kind ${kind}`,
        param,
      });
    }
  });

  test("an OutputShape that the function does not return is refused", async () => {
    const b = manualBridge();
    const load = b.bridge.load;
    b.bridge.load = (o) => load({ ...o, outputShape: { rows: 1, cols: 3 } });
    await expect(harness({ OutputShape: [2, 2] }, b)).rejects.toMatchObject({
      param: "OutputShape",
    });
  });

  test("a call still running past Budget is counted while it runs, once", async () => {
    const { h, b } = await harness({ Budget: 10 });
    expect(b.options).toMatchObject({ lateAfterMs: 10, hardLimitMs: 2000, memoryLimitMb: 4096 });
    h.push(ev(1, 1, 1));
    b.late(25);
    b.late(60);
    expect(h.text).toMatch(/pid 42 · call running for 60\.0 ms · .* · 1 over budget \(10\.0 ms\)/);
    expect(h.computeReports.map((r) => [r.ms, r.budgetMs])).toEqual([
      [25, 10],
      [60, 10],
    ]);
    b.answer();
    expect(h.text).toMatch(/pid 42 · p50 .* · 1 over budget/);
    expect(h.text).not.toMatch(/running for/);
  });

  test("HardLimit: default 10 × Budget (at least 2 s), or as given; MemoryLimit passed on", async () => {
    const { b } = await harness({ Budget: 500 });
    expect(b.options.hardLimitMs).toBe(5000);
    const { b: b2 } = await harness({ HardLimit: 300, MemoryLimit: 0 });
    expect(b2.options).toMatchObject({ hardLimitMs: 300, memoryLimitMb: 0, lateAfterMs: 10 });
  });

  test("under the virtual clock every input gets its call, and results wait for flush", async () => {
    const b = manualBridge();
    const h = await BlockHarness.create(
      Python,
      { Module: "m.py", Function: "f" },
      { inputs: [{ shape: vectorShape(2), rate: 100 }], io: { python: b.bridge }, virtual: true },
    );
    h.start();
    h.push(
      Frame.from(
        vectorShape(2),
        [1, 2, 3],
        [
          [1, 0],
          [2, 0],
          [3, 0],
        ],
      ),
    );
    h.push(ev(4, 4, 0));
    // One call in flight, three waiting: the engine waits for four results.
    expect(b.calls.map((c) => c.values[0])).toEqual([1]);
    expect(h.awaiting).toBe(4);
    b.answer();
    b.fail("ValueError: bad");
    expect(h.awaiting).toBe(2);
    b.answer();
    b.answer();
    expect(h.awaiting).toBe(0);
    expect(h.output().t).toEqual([]); // held until the engine flushes
    h.instance.flush?.();
    expect(h.output().t).toEqual([1, 2, 3, 4]);
    expect(h.output().v).toEqual([
      [2, 1],
      [2, 1], // hold: the failed call's output is the last good one
      [4, 1],
      [5, 1],
    ]);
    expect(h.text).not.toMatch(/skipped/);
    expect(h.warnings).toEqual([]);
    // A crash: the inputs wait for the restart; when the restart fails, they are given up.
    h.push(ev(5, 5, 0));
    h.push(ev(6, 6, 0));
    b.crash();
    expect(h.awaiting).toBe(1);
    b.restartFailed();
    expect(h.awaiting).toBe(0);
    h.push(ev(7, 7, 0));
    expect(h.awaiting).toBe(0);
    expect(h.text).toMatch(/2 skipped/);
    b.restarted();
    h.push(ev(8, 8, 0));
    expect(h.awaiting).toBe(1);
  });

  test("without a Python bridge (the browser build) it loads, says so and emits nothing", async () => {
    const h = await BlockHarness.create(
      Python,
      { Module: "m.py", Function: "f", OutputShape: [3, 1] },
      { inputs: [{ shape: matrixShape(4, 2), rate: 25 }] },
    );
    h.start();
    h.push(Frame.from(matrixShape(4, 2), [0], [[1, 2, 3, 4, 5, 6, 7, 8]]));
    expect(h.ports[0]!.shape).toEqual({ rows: 3, cols: 1 });
    expect(h.output().t).toEqual([]);
    expect(h.text).toMatch(/Python is not available here \(browser build\)/);
  });
});
