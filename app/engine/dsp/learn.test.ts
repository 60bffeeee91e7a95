// The learning kernels through the wasm module, against the same scikit-learn fixture as the Rust
// crate (core-wasm/learn/tests/fixtures/learn.json, from gen_learn.py) with the same tolerances:
// batch 1e-9 and incremental 1e-8, relative to the largest reference value. Needs the built
// module: `npm run build:wasm`.
import { readFileSync } from "node:fs";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";
import { beforeAll, describe, expect, it } from "vitest";

import { benchLearning, initDsp, LearningModel, type LearningModelOptions } from "./index";

const ROOT = join(dirname(fileURLToPath(import.meta.url)), "..", "..", "..");
const FIXTURES = join(ROOT, "core-wasm", "learn", "tests", "fixtures");

interface Data {
  n: number;
  d: number;
  m: number;
  x: number[];
  y: number[];
  xt: number[];
}
interface Case {
  name: string;
  alpha: number;
  intercept: boolean;
  weights: number[];
  bias: number[];
  predictions: number[];
  beta?: number;
  lambda?: number;
  lambda_eff?: number;
  incremental?: boolean;
  gamma?: number;
  features?: number;
  omega?: number[];
  offset?: number[];
}
interface Fixture {
  linear: Data;
  nonlinear: Data;
  ridge: Case[];
  weighted: Case[];
  rff: Case[];
}

const fx = JSON.parse(readFileSync(join(FIXTURES, "learn.json"), "utf8")) as Fixture;

beforeAll(() => initDsp(readFileSync(join(ROOT, "core-wasm", "pkg", "mosaic_core_bg.wasm"))));

/** max |a − b| / max |b|. */
function rel(a: ArrayLike<number>, b: readonly number[]): number {
  expect(a.length).toBe(b.length);
  let scale = 1e-300;
  for (const v of b) scale = Math.max(scale, Math.abs(v));
  let e = 0;
  for (let i = 0; i < b.length; i++) e = Math.max(e, Math.abs(a[i]! - b[i]!));
  return e / scale;
}

/** Rows [target, data] of a data set, as the Buffer's pairs output. */
function pairs(d: Data): Float64Array {
  const w = d.d + d.m;
  const p = new Float64Array(d.n * w);
  for (let i = 0; i < d.n; i++) {
    for (let o = 0; o < d.m; o++) p[i * w + o] = d.y[i * d.m + o]!;
    for (let k = 0; k < d.d; k++) p[i * w + d.m + k] = d.x[i * d.d + k]!;
  }
  return p;
}

/** Learns the data set one event per call, with trainPredict. */
function incremental(model: LearningModel, d: Data): void {
  const out = new Float64Array(d.m);
  const x = Float64Array.from(d.x);
  for (let i = 0; i < d.n; i++) {
    model.trainPredict(
      x.subarray(i * d.d, (i + 1) * d.d),
      d.y.slice(i * d.m, (i + 1) * d.m),
      out,
      1,
    );
  }
}

function predictions(model: LearningModel, d: Data): Float64Array {
  const n = d.xt.length / d.d;
  const out = new Float64Array(n * d.m);
  model.predict(Float64Array.from(d.xt), out, n);
  return out;
}

/** A fresh RFF model whose Ω and b are replaced by the fixture's, through its state. */
function rffWith(c: Case, d: Data): LearningModel {
  const model = new LearningModel({
    kind: "rff",
    inputs: d.d,
    outputs: d.m,
    features: c.features!,
    gamma: c.gamma!,
    lambda: c.alpha,
    intercept: c.intercept,
  });
  const state = model.saveState();
  let at = 0;
  for (const s of model.stateSections()) {
    if (s.name === "omega") state.set(c.omega!, at);
    if (s.name === "offset") state.set(c.offset!, at);
    at += s.length;
  }
  model.loadState(state);
  return model;
}

describe("LearningModel (wasm) vs scikit-learn", () => {
  it("ridge: batch (fitPairs) within 1e-9 and incremental (trainPredict) within 1e-8", () => {
    const d = fx.linear;
    for (const c of fx.ridge) {
      const o: LearningModelOptions = {
        kind: "ridge",
        inputs: d.d,
        outputs: d.m,
        lambda: c.alpha,
        intercept: c.intercept,
      };
      const batch = new LearningModel(o);
      expect(batch.fitPairs(pairs(d), d.n)).toBe(d.n);
      expect(rel(predictions(batch, d), c.predictions), c.name).toBeLessThanOrEqual(1e-9);
      const inc = new LearningModel(o);
      incremental(inc, d);
      expect(inc.samplesSeen()).toBe(d.n);
      expect(rel(predictions(inc, d), c.predictions), c.name).toBeLessThanOrEqual(1e-8);
      batch.dispose();
      inc.dispose();
    }
  });

  it("forgetting: incremental equals the weighted solution with λ_eff", () => {
    const d = fx.linear;
    for (const c of fx.weighted.filter((w) => w.incremental === true)) {
      const m = new LearningModel({
        kind: "ridge",
        inputs: d.d,
        outputs: d.m,
        lambda: c.lambda!,
        forgetting: c.beta!,
        intercept: c.intercept,
      });
      incremental(m, d);
      expect(m.effectiveLambda()).toBe(c.lambda_eff);
      expect(rel(predictions(m, d), c.predictions), c.name).toBeLessThanOrEqual(1e-8);
      m.dispose();
    }
  });

  it("RFF with scikit-learn's Ω and b: batch 1e-9, incremental 1e-8", () => {
    const d = fx.nonlinear;
    for (const c of fx.rff) {
      const batch = rffWith(c, d);
      expect(batch.dim).toBe(c.features);
      batch.fitPairs(pairs(d), d.n);
      expect(rel(predictions(batch, d), c.predictions), c.name).toBeLessThanOrEqual(1e-9);
      const inc = rffWith(c, d);
      incremental(inc, d);
      expect(rel(predictions(inc, d), c.predictions), c.name).toBeLessThanOrEqual(1e-8);
      batch.dispose();
      inc.dispose();
    }
  });
});

describe("LearningModel contracts", () => {
  const d = fx.linear;
  const options: LearningModelOptions[] = [
    { kind: "ridge", inputs: d.d, outputs: d.m, normalize: true, forgetting: 0.98 },
    { kind: "rff", inputs: d.d, outputs: d.m, features: 32, gamma: 0.05, seed: 2 ** 40 + 3 },
  ];

  it("one call of n events = n calls of one event, bit for bit; reset repeats", () => {
    const x = Float64Array.from(d.x);
    const target = [0.5, -1, 2];
    for (const o of options) {
      const a = new LearningModel(o);
      const pa = new Float64Array(d.n * d.m);
      expect(a.trainPredict(x, target, pa, d.n)).toBe(d.n);
      const b = new LearningModel(o);
      const pb = new Float64Array(d.n * d.m);
      const one = new Float64Array(d.m);
      for (let i = 0; i < d.n; i++) {
        b.trainPredict(x.subarray(i * d.d), target, one, 1);
        pb.set(one, i * d.m);
      }
      expect(Array.from(pb)).toEqual(Array.from(pa));
      expect(Array.from(b.saveState())).toEqual(Array.from(a.saveState()));
      a.reset();
      expect(a.samplesSeen()).toBe(0);
      const again = new Float64Array(d.n * d.m);
      a.trainPredict(x, target, again, d.n);
      expect(Array.from(again)).toEqual(Array.from(pa));
      a.dispose();
      b.dispose();
    }
  });

  it("state: sections, round trip, and refusals that say what is wrong", () => {
    const m = new LearningModel({ kind: "ridge", inputs: d.d, outputs: d.m });
    m.fitPairs(pairs(d), d.n);
    const names = m.stateSections().map((s) => s.name);
    expect(names).toEqual([
      "meta",
      "penalty",
      "x_mean",
      "y_mean",
      "scatter",
      "cross",
      "weights",
      "intercept",
      "fit_stats",
    ]);
    const state = m.saveState();
    expect(state.length).toBe(m.stateSections().reduce((s, x) => s + x.length, 0));
    const copy = new LearningModel({ kind: "ridge", inputs: d.d, outputs: d.m });
    copy.loadState(state);
    expect(rel(predictions(copy, d), Array.from(predictions(m, d)))).toBeLessThan(1e-12);
    const bad = state.slice();
    bad[3 + d.d + d.d + d.m + 1] += 1; // scatter[0][1]
    expect(() => copy.loadState(bad)).toThrow(/scatter\[1\]\[0\] differs/);
    expect(() => copy.loadState(state.subarray(1))).toThrow(/needs/);
    const r2 = new Float64Array(d.m);
    m.r2(r2);
    for (const v of r2) expect(v).toBeGreaterThan(0.9);
    m.dispose();
    copy.dispose();
    expect(() => m.predict(new Float64Array(d.d), new Float64Array(d.m), 1)).toThrow(
      /after dispose/,
    );
  });

  it("refuses bad options with the Rust message", () => {
    expect(() => new LearningModel({ kind: "ridge", inputs: 2, outputs: 1, lambda: 0 })).toThrow(
      /Lambda is 0/,
    );
    expect(() => new LearningModel({ kind: "rff", inputs: 2, outputs: 1, features: 5000 })).toThrow(
      /Features is 5000/,
    );
    expect(() => new LearningModel({ kind: "ridge", inputs: 0, outputs: 1 })).toThrow(/inputs/);
  });

  it("stays correct when the wasm memory grows", () => {
    const m = new LearningModel({ kind: "ridge", inputs: d.d, outputs: d.m, lambda: 1 });
    const views: LearningModel[] = [];
    const x = Float64Array.from(d.x);
    const out = new Float64Array(d.m);
    for (let i = 0; i < d.n; i++) {
      if (i % 60 === 0) {
        views.push(new LearningModel({ kind: "rff", inputs: 4, outputs: 4, features: 600 }));
      }
      m.trainPredict(x.subarray(i * d.d), d.y.slice(i * d.m, (i + 1) * d.m), out, 1);
    }
    expect(
      rel(predictions(m, d), fx.ridge.find((c) => c.alpha === 1 && c.intercept)!.predictions),
    ).toBeLessThan(1e-8);
    for (const v of views) v.dispose();
    m.dispose();
  });

  it("bench hook: ns per update and per prediction (printed, not asserted)", () => {
    const figures = benchLearning(() => performance.now(), { seconds: 0.02 });
    expect(figures.map((f) => `${f.kind} ${f.dim}`)).toEqual([
      "ridge 8",
      "ridge 64",
      "ridge 256",
      "rff 8",
      "rff 64",
      "rff 256",
    ]);
    for (const f of figures) {
      expect(f.updateNs).toBeGreaterThan(0);
      expect(f.predictNs).toBeGreaterThan(0);
    }
  });
});

interface LdaCase {
  name: string;
  shrinkage: number;
  d: number;
  m: number;
  x: number[];
  y: number[];
  xt: number[];
  scores: number[];
  class: number[];
}

describe("LearningModel kind lda (wasm) vs scikit-learn (lda.json, from gen_lda.py)", () => {
  const lda = JSON.parse(readFileSync(join(FIXTURES, "lda.json"), "utf8")) as { cases: LdaCase[] };
  it.each(lda.cases)("$name: trained sample by sample while predicting, then predicting", (c) => {
    for (const output of ["scores", "class"] as const) {
      const model = new LearningModel({
        kind: "lda",
        inputs: c.d,
        outputs: c.m,
        shrinkage: c.shrinkage,
        maxClasses: 8,
        ldaOutput: output,
      });
      const n = c.x.length / c.d;
      const out = new Float64Array(c.m);
      for (let i = 0; i < n; i++) {
        const x = Float64Array.from(c.x.slice(i * c.d, (i + 1) * c.d));
        model.trainPredict(x, c.y.slice(i * c.m, (i + 1) * c.m), out, 1);
      }
      expect(model.samplesSeen()).toBe(n);
      const nt = c.xt.length / c.d;
      const got = new Float64Array(nt * c.m);
      model.predict(Float64Array.from(c.xt), got, nt);
      const want = output === "scores" ? c.scores : c.class;
      const err = Math.max(...Array.from(got, (v, i) => Math.abs(v - want[i]!)));
      expect(err).toBeLessThanOrEqual(1e-9);
      model.dispose();
    }
  });
});
