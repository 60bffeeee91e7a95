/**
 * The original MOSAIC's examples 6 (batch learning with a stimulus) and 7 (incremental learning,
 * then a target achievement control test) end to end, with our own files of the same structure
 * (tests/fixtures/mosaic-original/batch-with-stimulus.yaml, incremental-with-tac.yaml): loaded as
 * written, devices simulated (app/engine/pipeline/simulate.ts) with the network outputs kept, run
 * under the virtual clock with a script of what the experimenter and the participant do (start
 * the stimulus, hold a Trigger label, make a gesture, build the model). The BlenderArm datagrams
 * go over real loopback UDP to an independent reader written from the original's format
 * (tests/integration/blender_decode.py) and are checked against the ControlAlgorithm's output;
 * the models are checked on what they predict for gestures they were trained on.
 */
import { spawn, spawnSync, type ChildProcess } from "node:child_process";
import { readFileSync } from "node:fs";
import { join } from "node:path";
import { createInterface } from "node:readline";
import { afterEach, beforeAll, describe, expect, test } from "vitest";
import { nodeUdpBridge } from "../../native-bridges/udp";
import { catalog } from "../../app/blocks/catalog";
import { VirtualClock } from "../../app/engine/clock";
import { formatDiagnostic } from "../../app/engine/diagnostics";
import type { Frame } from "../../app/engine/frame";
import { loadPipeline } from "../../app/engine/pipeline/loader";
import { withSimulatedDevices } from "../../app/engine/pipeline/simulate";
import { Runtime } from "../../app/engine/runtime/runtime";
import { runVirtual } from "../../app/engine/runtime/virtual";
import { noResources } from "../../app/engine/testing";
import { initDspForTests } from "../support/wasm";
import { ROOT } from "./helpers";

const DIR = join(ROOT, "tests/fixtures/mosaic-original");
const hasPython = spawnSync("python3", ["--version"]).status === 0;

const cleanup: (() => void)[] = [];
afterEach(() => {
  for (const c of cleanup.splice(0)) c();
});
beforeAll(() => initDspForTests());

interface Decoded {
  values?: number[];
  error?: string;
}

/** tests/integration/blender_decode.py on a free loopback port. */
async function blenderReader(): Promise<{ port: number; result: Promise<Decoded[]> }> {
  const proc: ChildProcess = spawn(
    "python3",
    [join(ROOT, "tests/integration/blender_decode.py"), "--idle", "1.5", "--timeout", "60"],
    { stdio: ["ignore", "pipe", "inherit"] },
  );
  cleanup.push(() => proc.kill());
  const lines: string[] = [];
  const rl = createInterface({ input: proc.stdout! });
  let onPort: (p: number) => void = () => {};
  const portP = new Promise<number>((r) => (onPort = r));
  rl.on("line", (l) => {
    if (lines.length === 0) onPort((JSON.parse(l) as { port: number }).port);
    lines.push(l);
  });
  const result = new Promise<Decoded[]>((res) =>
    proc.on("close", () => res(lines.slice(1).map((l) => JSON.parse(l) as Decoded))),
  );
  return { port: await portP, result };
}

/** One step of the script: at virtual time `t` (s from the start), do something. */
type Step = [t: number, what: (rt: Runtime) => unknown];

interface Run {
  rt: Runtime;
  /** Every event of the recorded outputs ("block" or "block.port"): [t, ...values], t from the start. */
  seen: Map<string, number[][]>;
  infos: string[];
  /** Blocks that reported an error: "name: message". */
  errors: string[];
}

const T0 = 1_700_000_000;

/**
 * Loads a fixture (with `replace` applied to its text), simulates its devices (network outputs
 * kept when `udp`), and runs the script under the virtual clock until `until`, in slices of
 * 0.2 s: after each, the steps that are due run, then `each` (a participant reacting to what
 * the pipeline shows), then, with `udp`, a turn of the event loop lets the datagrams leave.
 */
async function runScripted(
  file: string,
  opts: {
    script: Step[];
    each?: (rt: Runtime, run: Run) => void;
    until: number;
    record: string[];
    udp: boolean;
    replace?: [string, string][];
  },
): Promise<Run> {
  let text = readFileSync(join(DIR, file), "utf8");
  for (const [a, b] of opts.replace ?? []) {
    expect(text).toContain(a);
    text = text.replace(a, b);
  }
  const loaded = withSimulatedDevices(loadPipeline(text, file, catalog), catalog, {
    keepNetwork: opts.udp,
  });
  if (!loaded.spec) throw new Error(loaded.diagnostics.map(formatDiagnostic).join("\n"));
  const clock = new VirtualClock(T0);
  const created = await Runtime.create({
    spec: loaded.spec,
    catalog,
    clock,
    virtual: true,
    resources: noResources,
    ...(opts.udp ? { io: { udp: nodeUdpBridge() } } : {}),
    ignorePlacement: true,
  });
  if (!created.runtime) throw new Error(created.diagnostics.map(formatDiagnostic).join("\n"));
  const rt = created.runtime;
  const run: Run = {
    rt,
    seen: new Map(),
    infos: loaded.diagnostics.filter((d) => d.severity === "info").map((d) => d.message),
    errors: [],
  };
  for (const name of opts.record) {
    const rows: number[][] = [];
    run.seen.set(name, rows);
    const [block, port] = name.split(".");
    rt.tap(block!, port, (f: Frame) => {
      for (let i = 0; i < f.n; i++) {
        rows.push([f.t[i]! - T0, ...f.v.subarray(i * f.stride, (i + 1) * f.stride)]);
      }
    });
  }
  rt.start();
  const steps = [...opts.script].sort((a, b) => a[0] - b[0]);
  for (let at = 0; at < opts.until;) {
    at = Math.min(opts.until, at + 0.2);
    while (runVirtual(rt, clock, T0 + at) === "yield");
    while (steps.length > 0 && steps[0]![0] <= at + 1e-9) steps.shift()![1](rt);
    opts.each?.(rt, run);
    if (opts.udp) await new Promise((r) => setTimeout(r, 2));
  }
  rt.stop();
  run.errors = rt
    .telemetry()
    .blocks.flatMap((b) => (b.errors > 0 ? [`${b.name}: ${b.lastError}`] : []));
  return run;
}

/** The last recorded event of `name` at or before `t`. */
const at = (run: Run, name: string, t: number): number[] => {
  const rows = run.seen.get(name)!.filter((r) => r[0]! <= t);
  expect(rows.length, `${name} has no event before ${t} s`).toBeGreaterThan(0);
  return rows[rows.length - 1]!.slice(1);
};

/**
 * The simulated participant follows the cue shown (a Selector of the Stimulus): a hand closing
 * (fingers, 0–5) makes a fist, the wrist extending (7) an extension, anything else rest.
 */
const follow =
  (emg: string, cue: string) =>
  (rt: Runtime, run: Run): void => {
    const rows = run.seen.get(cue)!;
    const v = rows[rows.length - 1];
    const want =
      v === undefined ? "rest" : v[1]! > 0.5 ? "fist" : v[8]! > 0.5 ? "extension" : "rest";
    if (want !== (run as Run & { gesture?: string }).gesture) {
      (run as Run & { gesture?: string }).gesture = want;
      rt.invoke(emg, "setGesture", want);
    }
  };

/**
 * What the BlenderArm sends for one event of the ControlAlgorithm (11 degrees of actuation,
 * 0–100, in the DOAs order), as the original's BlenderArm computed it: fingers / 100, the wrist
 * axes / 50 − 1, pronation/supination negated.
 */
const blenderOf = (c: number[]): number[] => [
  ...c.slice(0, 6).map((x) => x / 100),
  c[6]! / 50 - 1,
  c[7]! / 50 - 1,
  -(c[8]! / 50 - 1),
];

/** Decoded datagrams equal the arm commands of the recorded control events, in order. */
function expectDatagrams(decoded: Decoded[], control: number[][]): void {
  expect(control.length).toBeGreaterThan(100);
  expect(decoded.filter((d) => d.error !== undefined)).toEqual([]);
  expect(decoded.length).toBe(control.length);
  decoded.forEach((d, i) => {
    const want = blenderOf(control[i]!.slice(1));
    d.values!.forEach((v, k) => expect(v, `datagram ${i}, value ${k}`).toBeCloseTo(want[k]!, 12));
  });
}

describe("example 7: incremental learning with a Trigger, then a TAC test", () => {
  test.skipIf(!hasPython)(
    "train by holding labels, then follow the stimulus: predictions, TAC successes, datagrams",
    async () => {
      const learnerArm = await blenderReader();
      const targetArm = await blenderReader();
      const gesture =
        (g: string): Step[1] =>
        (rt) =>
          rt.invoke("emg", "setGesture", g);
      const hold =
        (label: string): Step[1] =>
        (rt) =>
          rt.invoke("labels", "start", label);
      const release: Step[1] = (rt) => rt.invoke("labels", "stop");
      const run = await runScripted("incremental-with-tac.yaml", {
        // The experimenter holds a label while the participant makes its gesture, then starts
        // the test; the participant follows the cues from then on.
        script: [
          [1, hold("relax")],
          [4, release],
          [5, gesture("fist")],
          [6, hold("grip")],
          [9, release],
          [9.4, gesture("rest")],
          [10.4, gesture("extension")],
          [11.4, hold("extend")],
          [14.4, release],
          [15, gesture("rest")],
          [16, (rt) => rt.invoke("targets", "start")],
        ],
        each: (rt, r) => {
          if (r.seen.get("target_vector")!.length > 0) follow("emg", "target_vector")(rt, r);
        },
        until: 50,
        record: [
          "learner",
          "learner_control",
          "target_vector",
          "target_control",
          "score.trial",
          "targets.trigger",
        ],
        udp: true,
        replace: [
          ["localhost, 3334", `localhost, ${learnerArm.port}`],
          ["localhost, 3333", `localhost, ${targetArm.port}`],
        ],
      });
      expect(run.errors).toEqual([]);
      expect(run.infos).toEqual([
        "block 'emg' (Myo) simulated by EmgSimulator, 8 channels at 200 Hz (its timer's); gesture keys in the app",
      ]);

      // Trained on the three labels: the gestures give their targets.
      const grip = at(run, "learner", 8.5);
      const ext = at(run, "learner", 13.9);
      expect(Math.min(...grip.slice(0, 6))).toBeGreaterThan(0.7);
      expect(grip[7]).toBeLessThan(0.3);
      expect(ext[7]).toBeGreaterThan(0.6);
      expect(Math.max(...ext.slice(0, 6))).toBeLessThan(0.3);

      // The test: two captures (the Stimulus's trigger: target at the start, NaN at the end).
      const captures = run.seen.get("targets.trigger")!;
      const starts = captures.filter((r) => !Number.isNaN(r[1]!)).map((r) => r[0]!);
      const ends = captures.filter((r) => Number.isNaN(r[1]!)).map((r) => r[0]!);
      expect(starts).toHaveLength(2);
      expect(ends).toHaveLength(2);
      // The participant reached and held each target: a successful TAC trial while the cue held
      // it (its hold and capture phases: the TAC, wired to the cue as MOSAIC's, starts a trial
      // whenever the cue's target changes).
      const trials = run.seen.get("score.trial")!;
      for (let k = 0; k < 2; k++) {
        const won = trials.filter(
          (r) => r[0]! > starts[k]! - 2 && r[0]! <= ends[k]! && r[2] === 1 && r[5]! <= 0.35,
        );
        expect(won.length, `capture ${k + 1}`).toBeGreaterThan(0);
      }

      // Both arms: what the independent reader decoded is the ControlAlgorithm's output mapped.
      expectDatagrams(await learnerArm.result, run.seen.get("learner_control")!);
      expectDatagrams(await targetArm.result, run.seen.get("target_control")!);
      run.rt.dispose();
    },
    120_000,
  );
});

describe("example 6: batch learning with a stimulus", () => {
  test.skipIf(!hasPython)(
    "the stimulus records three clusters, the model is built and predicts the gestures; datagrams",
    async () => {
      const modelArm = await blenderReader();
      const cueArm = await blenderReader();
      const run = await runScripted("batch-with-stimulus.yaml", {
        script: [
          [1, (rt) => rt.invoke("cues", "start")],
          // After the three cues (3 × 8.5 s): MOSAIC's Build model.
          [28, (rt) => rt.invoke("model", "train")],
          [29, (rt) => rt.invoke("armband", "setGesture", "fist")],
          [32, (rt) => rt.invoke("armband", "setGesture", "extension")],
          [35, (rt) => rt.invoke("armband", "setGesture", "rest")],
        ],
        each: (rt, r) => {
          if (r.seen.get("cue_vector")!.length > 0 && r.seen.get("cue_vector")!.at(-1)![0]! < 27)
            follow("armband", "cue_vector")(rt, r);
        },
        until: 38,
        record: ["cue_vector", "cue_control", "model", "model_control", "capture"],
        udp: true,
        replace: [
          ["localhost, 3334", `localhost, ${modelArm.port}`],
          ["localhost, 3333", `localhost, ${cueArm.port}`],
        ],
      });
      expect(run.errors).toEqual([]);
      // Three captures recorded: target at the start, NaN at the end.
      const capture = run.seen.get("capture")!;
      expect(capture.filter((r) => !Number.isNaN(r[1]!))).toHaveLength(3);
      expect(capture.filter((r) => Number.isNaN(r[1]!))).toHaveLength(3);
      const model = run.rt.telemetry().blocks.find((b) => b.name === "model")!;
      expect(model.text).toMatch(/^fitted on \d+ rows/);

      const fist = at(run, "model", 31.9);
      const ext = at(run, "model", 34.9);
      const rest = at(run, "model", 37.9);
      expect(Math.min(...fist.slice(0, 6))).toBeGreaterThan(0.7);
      expect(fist[7]).toBeLessThan(0.3);
      expect(ext[7]).toBeGreaterThan(0.7);
      expect(Math.max(...ext.slice(0, 6))).toBeLessThan(0.3);
      expect(Math.max(...rest.map(Math.abs))).toBeLessThan(0.3);

      expectDatagrams(await modelArm.result, run.seen.get("model_control")!);
      expectDatagrams(await cueArm.result, run.seen.get("cue_control")!);
      run.rt.dispose();
    },
    120_000,
  );
});
