/**
 * The human-in-the-loop training example (pipelines/examples/training.yaml), run by the real CLI
 * under the virtual clock: a simulated participant follows a Stimulus protocol while an
 * IncrementalPredictor learns from the capture phases; then, in a scripted held-out session
 * where nothing trains any more, the predictions must follow the participant's gestures.
 */
import { copyFileSync, existsSync, readFileSync } from "node:fs";
import { join } from "node:path";
import { beforeAll, describe, expect, test } from "vitest";
import { loadModel } from "../../app/blocks/learning/model-file";
import { initDspForTests } from "../support/wasm";
import { jsonLines, requireBuild, ROOT, runCli, tempDir } from "./helpers";

beforeAll(() => {
  requireBuild();
  initDspForTests();
});

const PIPELINE = join(ROOT, "pipelines/examples/training.yaml");
const GESTURES = ["fist", "open", "pinch", "flexion", "extension"];
/** The protocol: 6 labels × 3 repetitions of 6.5 s; the scripted session: 120–170 s. */
const TEST_FROM = 120;
const TEST_TO = 170;
const DURATION = 172;
/** Seconds after each scripted change left out of the steady-state figures (reaction 250 ms + envelope). */
const SETTLE = 1;

type Rows = number[][];
const rows = (file: string): Rows =>
  readFileSync(file, "utf8")
    .trim()
    .split("\n")
    .map((l) => l.split(",").map(Number));

/** R² of predictions `p` against targets `y`, per column. */
function r2(p: Rows, y: Rows): number[] {
  return y[0]!.map((_, k) => {
    const m = y.reduce((s, r) => s + r[k]!, 0) / y.length;
    let se = 0;
    let st = 0;
    y.forEach((r, i) => {
      se += (p[i]![k]! - r[k]!) ** 2;
      st += (r[k]! - m) ** 2;
    });
    return 1 - se / st;
  });
}

/** The class of a prediction vector: the largest output if it exceeds 0.5, else rest (-1). */
const classOf = (p: number[]): number => {
  let best = 0;
  for (let k = 1; k < p.length; k++) if (p[k]! > p[best]!) best = k;
  return p[best]! > 0.5 ? best : -1;
};

describe("training example: Stimulus → simulated participant → IncrementalPredictor → control", () => {
  test("after training, predictions in the held-out session follow the gestures; the model file loads", () => {
    const dir = tempDir();
    copyFileSync(PIPELINE, join(dir, "training.yaml"));
    const r = runCli(
      ["run", "training.yaml", "--clock", "virtual", "--duration", String(DURATION), "--json"],
      { cwd: dir, timeoutMs: 120_000 },
    );
    expect(r.stderr).toBe("");
    expect(r.code).toBe(0);
    const summary = jsonLines(r.stdout).find((l) => l.type === "summary") as unknown as {
      reason: string;
      blocks: { name: string; text: string; errors: number }[];
    };
    expect(summary.reason).toBe("finished");
    for (const b of summary.blocks) expect([b.name, b.errors]).toEqual([b.name, 0]);
    const text = (name: string) => summary.blocks.find((b) => b.name === name)!.text;
    expect(text("Cues")).toBe("done: 18 cues");
    expect(text("Session")).toContain("schedule 10/10");
    expect(text("Predictor")).toMatch(/^trained on 1,?350 samples/);

    const log = (name: string) => rows(join(dir, "training", `${name}.txt`));
    // Training: 18 captures of 3 s at 25 Hz, 3 per label, labelled with the label's target.
    const recorded = log("Recorder");
    expect(recorded).toHaveLength(18 * 75);
    const perLabel = new Map<string, number>();
    for (const row of recorded) {
      const key = row.slice(1, 6).join();
      perLabel.set(key, (perLabel.get(key) ?? 0) + 1);
    }
    expect([...perLabel.values()]).toEqual(new Array(6).fill(225));
    expect(recorded.at(-1)![0]).toBeLessThan(TEST_FROM);
    const phases = log("Cues.phase");
    expect(phases.at(-1)![1]).toBe(5); // the protocol ended
    expect(phases.at(-1)![0]).toBeLessThan(TEST_FROM);

    // The held-out session: the script's label at every prediction (rest = -1 between gestures).
    const script = log("Session.label");
    expect(script).toHaveLength(20);
    const at = (t: number): { label: number; since: number } => {
      let label = -1;
      let since = Infinity;
      for (const [ts, l] of script) {
        if (ts! > t) break;
        label = Number.isNaN(l) ? -1 : l!;
        since = t - ts!;
      }
      return { label, since };
    };
    const predictions = log("Predictor");
    const control = log("Control");
    expect(control.map((c) => c[0])).toEqual(predictions.map((p) => p[0]));
    const held: { p: number[]; y: number[]; label: number; c: number[] }[] = [];
    const all: { p: number[]; y: number[]; label: number }[] = [];
    predictions.forEach((row, i) => {
      const t = row[0]!;
      if (t < TEST_FROM || t >= TEST_TO) return;
      const { label, since } = at(t);
      const y = GESTURES.map((_, k) => (k === label ? 1 : 0));
      const p = row.slice(1);
      all.push({ p, y, label });
      if (since >= SETTLE) held.push({ p, y, label, c: control[i]!.slice(1) });
    });
    expect(all).toHaveLength((TEST_TO - TEST_FROM) * 25);
    const r2Held = r2(
      held.map((h) => h.p),
      held.map((h) => h.y),
    );
    const r2All = r2(
      all.map((h) => h.p),
      all.map((h) => h.y),
    );
    const accuracy = (set: { p: number[]; label: number }[]) =>
      set.filter((h) => classOf(h.p) === h.label).length / set.length;
    const fmt = (v: number[]) => v.map((x) => x.toFixed(3)).join(", ");
    console.log(
      `training example, held-out session (${held.length} predictions at 25 Hz, ${SETTLE} s after ` +
        `each change left out): R² per DoF [${GESTURES.join(", ")}] = [${fmt(r2Held)}], ` +
        `classification ${(accuracy(held) * 100).toFixed(1)} %; every prediction ` +
        `(${all.length}): R² [${fmt(r2All)}], classification ${(accuracy(all) * 100).toFixed(1)} %`,
    );
    for (const v of r2Held) expect(v).toBeGreaterThan(0.85);
    expect(accuracy(held)).toBeGreaterThanOrEqual(0.95);
    expect(accuracy(all)).toBeGreaterThanOrEqual(0.75);

    // The control: hand closes on fist and opens on open, pinch, wrist flexion/extension.
    const meanControl = (label: number) => {
      const sel = held.filter((h) => h.label === label);
      return [0, 1, 2].map((k) => sel.reduce((s, h) => s + h.c[k]!, 0) / sel.length);
    };
    const [rest, fist, open, pinch, flexion, extension] = [-1, 0, 1, 2, 3, 4].map(meanControl);
    console.log(
      "training example, mean control [Hand, Pinch, Wrist] per gesture: " +
        [rest, fist, open, pinch, flexion, extension]
          .map((c, i) => `${["rest", ...GESTURES][i]} [${c!.map((x) => x.toFixed(0)).join(", ")}]`)
          .join("; "),
    );
    expect(rest![0]).toBeCloseTo(50, -1);
    expect(rest![1]).toBeLessThan(10);
    expect(rest![2]).toBeCloseTo(50, -1);
    expect(fist![0]).toBeGreaterThan(80);
    expect(open![0]).toBeLessThan(20);
    expect(pinch![1]).toBeGreaterThan(60);
    expect(flexion![2]).toBeGreaterThan(80);
    expect(extension![2]).toBeLessThan(20);

    // The model saved after the last capture loads, and predicts what the block predicted.
    const file = join(dir, "Predictor.model.json");
    expect(existsSync(file)).toBe(true);
    const { model } = loadModel(readFileSync(file, "utf8"), file, {
      inputs: 8,
      outputs: 5,
      inputName: "Envelope",
      targetName: "Cues.trigger",
    });
    expect(model.options.kind).toBe("ridge");
    expect(model.samplesSeen()).toBe(18 * 75);
    const envelope = log("Envelope");
    const out = new Float64Array(5);
    let checked = 0;
    envelope.forEach((row, i) => {
      if (row[0]! < TEST_FROM || i % 50 !== 0) return;
      model.predict(Float64Array.from(row.slice(1)), out, 1);
      const logged = predictions.find((p) => p[0] === row[0])!;
      for (let k = 0; k < 5; k++) expect(out[k]).toBeCloseTo(logged[k + 1]!, 12);
      checked++;
    });
    expect(checked).toBeGreaterThan(20);
    model.dispose();
  }, 120_000);
});
