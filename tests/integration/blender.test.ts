/**
 * BlenderArm on real loopback UDP, through the real CLI and engine workers (dist/): a pipeline in
 * the original MOSAIC's positional syntax drives two arms, one through a ControlAlgorithm and one
 * with a plain prediction vector, and an independent Python reader written from the original's
 * format (tests/integration/blender_decode.py) checks every datagram against the commands the
 * block logged, and against the ControlAlgorithm's log mapped by hand.
 */
import { spawn, spawnSync, type ChildProcess } from "node:child_process";
import { readFileSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { createInterface } from "node:readline";
import { afterEach, describe, expect, test } from "vitest";
import { jsonLines, requireBuild, ROOT, runCli, tempDir } from "./helpers";

const cleanup: (() => void)[] = [];
afterEach(() => {
  for (const c of cleanup.splice(0)) c();
});

const hasPython = spawnSync("python3", ["--version"]).status === 0;

interface Decoded {
  values?: number[];
  named?: Record<string, number>;
  error?: string;
}

async function blenderReader(): Promise<{
  port: number;
  proc: ChildProcess;
  result: Promise<Decoded[]>;
}> {
  const proc = spawn(
    "python3",
    [join(ROOT, "tests/integration/blender_decode.py"), "--idle", "1.5", "--timeout", "30"],
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
  return { port: await portP, proc, result };
}

const readLog = (file: string): number[][] =>
  readFileSync(file, "utf8")
    .trim()
    .split("\n")
    .filter((l) => l !== "")
    .map((l) => l.split(",").map(Number));

describe("BlenderArm on loopback, real host", () => {
  test.skipIf(!hasPython)(
    "datagrams decoded by an independent reader equal the logged commands and the control mapping",
    async () => {
      requireBuild();
      const dir = tempDir("mosaic-blender-");
      const viaControl = await blenderReader();
      const plain = await blenderReader();
      const file = join(dir, "blender.yaml");
      writeFileSync(
        file,
        `
timer: { Type: ScheduledTimer, DesiredRate: 50 }
predictions: { Type: SinGenerator, Inputs: [ timer ], Params: [ 12, 1, 2 ], Path: logs }
control: { Type: ControlAlgorithm, Inputs: [ predictions ], Params: [ algorithm:DirectControl ], Path: logs }
skin_arm: { Type: BlenderArm, Inputs: [ control ], Params: [ localhost, ${viaControl.port} ], Path: logs }
white_arm: { Type: BlenderArm, Inputs: [ predictions ], Params: [ 127.0.0.1, ${plain.port} ], Path: logs }
`,
      );
      const r = runCli(["run", file, "--duration", "1.5", "--json"], { timeoutMs: 60_000 });
      expect(r.code, r.stderr).toBe(0);
      const events = jsonLines(r.stdout).filter((l) => l.type === "event" || l.type === "fatal");
      // The one expected warning: the 12 predictions leave the elbows at rest.
      expect(events.map((e) => String(e.message))).toEqual([
        expect.stringMatching(/12 predictions; at rest \(no prediction\): ElbowFlexion/),
      ]);

      const control = readLog(join(dir, "logs", "control.txt"));
      const skin = readLog(join(dir, "logs", "skin_arm.txt"));
      const white = readLog(join(dir, "logs", "white_arm.txt"));
      const preds = readLog(join(dir, "logs", "predictions.txt"));
      expect(skin.length).toBeGreaterThan(50);

      const a = await viaControl.result;
      const b = await plain.result;
      expect(a.filter((d) => d.error !== undefined)).toEqual([]);
      expect(b.filter((d) => d.error !== undefined)).toEqual([]);
      expect(a.length).toBe(skin.length);
      expect(b.length).toBe(white.length);
      // What went over the wire is what the block logged, value for value, in order.
      a.forEach((d, i) => expect(d.values).toEqual(skin[i]!.slice(1)));
      b.forEach((d, i) => expect(d.values).toEqual(white[i]!.slice(1)));

      // The mapping, by hand from the original's formulas: fingers /100, wrist axes /50 − 1
      // (pronation/supination negated), from the ControlAlgorithm's DOAs-ordered log.
      a.forEach((d, i) => {
        const c = control[i]!.slice(1);
        const n = d.named!;
        expect(n.thumb_flexion).toBeCloseTo(c[0]! / 100, 12);
        expect(n.little).toBeCloseTo(c[5]! / 100, 12);
        expect(n.wrist_flexion_extension).toBeCloseTo(c[6]! / 50 - 1, 12);
        expect(n.wrist_ulnar_radial).toBeCloseTo(c[7]! / 50 - 1, 12);
        expect(n.wrist_supination_pronation).toBeCloseTo(-(c[8]! / 50 - 1), 12);
      });
      // The plain vector takes the same route (DirectControl) without the ControlAlgorithm.
      b.forEach((d, i) => {
        const p = preds[i]!.slice(1);
        // Each prediction is an activation clamped to 0..1.
        const a01 = (x: number) => Math.min(1, Math.max(0, x));
        expect(d.values![2]).toBeCloseTo(a01(p[2]!), 12);
        expect(d.values![6]).toBeCloseTo(a01(p[7]!) - a01(p[6]!), 12);
        expect(d.values![8]).toBeCloseTo(-(a01(p[8]!) - a01(p[9]!)), 12);
      });
      expect(b.map((d) => d.values)).toEqual(a.map((d) => d.values));
    },
    90_000,
  );
});
