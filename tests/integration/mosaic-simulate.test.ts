/**
 * `--simulate-devices` through the real CLI (dist/): every file of tests/fixtures/mosaic-original
 * (our own files in the original MOSAIC's layouts, names and device types) validates, and runs
 * with its devices simulated, exit 0 and no block error; one info line per device says what it
 * became. Without the switch the devices say that they are not reachable and what to do, and the
 * rest of the pipeline runs.
 */
import { readdirSync } from "node:fs";
import { join } from "node:path";
import { beforeAll, describe, expect, test } from "vitest";
import { jsonLines, requireBuild, runCli, tempDir } from "./helpers";

const DIR = "tests/fixtures/mosaic-original";
const FILES = readdirSync(DIR)
  .filter((f) => f.endsWith(".yaml"))
  .sort()
  .map((f) => join(DIR, f));

/** The info lines of the simulation stage, as `file:line:col: info: …`. */
const infos = (stderr: string): string[] =>
  stderr.split("\n").filter((l) => / info: block '/.test(l));

beforeAll(() => requireBuild());

describe("mosaic validate", () => {
  test("every file validates, with and without --simulate-devices", () => {
    const plain = runCli(["validate", ...FILES], { timeoutMs: 120_000 });
    expect(plain.code, plain.stderr).toBe(0);
    expect(infos(plain.stderr)).toEqual([]);
    const sim = runCli(["validate", "--simulate-devices", ...FILES], { timeoutMs: 120_000 });
    expect(sim.code, sim.stderr).toBe(0);
    expect(infos(sim.stderr).map((l) => l.replace(/^.*mosaic-original\//, ""))).toEqual([
      "batch-with-stimulus.yaml:9:1: info: block 'armband' (Myo) simulated by EmgSimulator, 8 channels at 200 Hz (its timer's); gesture keys in the app",
      "batch-with-stimulus.yaml:31:1: info: block 'cue_arm' (BlenderArm) replaced by SimulatedOutput, counting the datagrams it would have sent to localhost:3333",
      "batch-with-stimulus.yaml:40:1: info: block 'model_arm' (BlenderArm) replaced by SimulatedOutput, counting the datagrams it would have sent to localhost:3334",
      "device-types.yaml:6:1: info: block 'probes' (Muovi) simulated by EmgSimulator, 64 channels at 2000 Hz (its timer's; gesture keys in the app)",
      "device-types.yaml:18:1: info: block 'probe' (MuoviSingleProbe) simulated by EmgSimulator probe_emg (32 channels at 2000 Hz) framed by a SlidingWindow into [10, 32] every 10 samples (200 Hz)",
      "device-types.yaml:19:1: info: block 'trigno' (Delsys) simulated by EmgSimulator, 16 channels at 200 Hz (its timer's; gesture keys in the app)",
      "device-types.yaml:20:1: info: block 'forces' (DLR_ADCBT) simulated by SinGenerator, 4 channels at 200 Hz (its timer's)",
      "device-types.yaml:21:1: info: block 'imu' (NilsPod) simulated by ImuSimulator, 6 values at 200 Hz (its timer's)",
      "incremental-with-tac.yaml:8:1: info: block 'emg' (Myo) simulated by EmgSimulator, 8 channels at 200 Hz (its timer's); gesture keys in the app",
      "incremental-with-tac.yaml:32:1: info: block 'learner_arm' (BlenderArm) replaced by SimulatedOutput, counting the datagrams it would have sent to localhost:3334",
      "incremental-with-tac.yaml:43:1: info: block 'target_arm' (BlenderArm) replaced by SimulatedOutput, counting the datagrams it would have sent to localhost:3333",
      "old-names.yaml:15:1: info: block 'arm' (Myo) simulated by EmgSimulator, 8 channels at 200 Hz (its timer's); gesture keys in the app",
      "streamlined-sender.yaml:5:1: info: block 'upper' (Myo) simulated by EmgSimulator, 8 channels at 200 Hz (its timer's); gesture keys in the app",
      "streamlined-sender.yaml:6:1: info: block 'lower' (Myo) simulated by EmgSimulator, 8 channels at 200 Hz (its timer's); gesture keys in the app",
      "streamlined-sender.yaml:32:1: info: block 'sender' (UdpSender) replaced by SimulatedOutput, counting the datagrams it would have sent to localhost:11000",
    ]);
  });

  test("--keep-network needs --simulate-devices", () => {
    const r = runCli(["validate", "--keep-network", FILES[0]!]);
    expect(r.code).toBe(2);
    expect(r.stderr).toContain("--keep-network only applies with --simulate-devices");
  });
});

describe("mosaic run --simulate-devices", () => {
  for (const file of FILES) {
    test(`${file}: 3 virtual seconds, exit 0, no block error`, () => {
      const logs = tempDir();
      const r = runCli(
        [
          "run",
          file,
          "--simulate-devices",
          "--clock",
          "virtual",
          "--duration",
          "3",
          "--json",
          "--log-dir",
          logs,
        ],
        { timeoutMs: 120_000 },
      );
      expect(r.code, r.stderr).toBe(0);
      const lines = jsonLines(r.stdout);
      expect(lines.filter((l) => l.type === "event" && l.level === "error")).toEqual([]);
      const summary = lines.find((l) => l.type === "summary") as {
        exitCode: number;
        blocks: {
          name: string;
          type: string;
          errors: number;
          events: number;
          desiredRate: number;
        }[];
      };
      expect(summary.exitCode).toBe(0);
      expect(summary.blocks.filter((b) => b.errors > 0)).toEqual([]);
      // No device block is left: each became its simulator.
      const devices = ["Myo", "Muovi", "MuoviSingleProbe", "Delsys", "DLR_ADCBT", "NilsPod"];
      expect(summary.blocks.filter((b) => devices.includes(b.type))).toEqual([]);
      // Every simulated source produced its 3 seconds of events.
      const simulated = infos(r.stderr)
        .filter((l) => / simulated by /.test(l))
        .map((l) => /block '([^']+)'/.exec(l)![1]!);
      for (const name of simulated) {
        const b = summary.blocks.find((x) => x.name === name)!;
        expect(b.events, name).toBeGreaterThanOrEqual(Math.round(3 * b.desiredRate));
      }
    }, 120_000);
  }
});

describe("without --simulate-devices", () => {
  test("each device says it is not reachable and what to do; the pipeline runs, exit 0", () => {
    const r = runCli(
      ["run", join(DIR, "device-types.yaml"), "--duration", "1", "--json", "--log-dir", tempDir()],
      { timeoutMs: 60_000 },
    );
    expect(r.code, r.stderr).toBe(0);
    const all = jsonLines(r.stdout).filter((l) => l.type === "event" && l.level === "warning");
    // The Muovi blocks speak their protocols: within the 1 s run the SyncStation's address may or
    // may not have failed yet (an unreachable network fails at once, a silent one after 3 s), and
    // the single probe's block listens and warns after 5 s without a probe.
    const muovi = all.filter((w) => w.block === "probes" || w.block === "probe");
    for (const w of muovi) {
      expect(String(w.message)).toMatch(
        w.block === "probes"
          ? /SyncStation at 192\.168\.76\.1:54320 not reachable: .* --simulate-devices/
          : /Muovi probe: .*54321.* --simulate-devices/,
      );
    }
    const warnings = all.filter((w) => !muovi.includes(w));
    expect(warnings.map((w) => w.block).sort()).toEqual(["forces", "imu", "trigno"]);
    for (const w of warnings) {
      expect(String(w.message)).toMatch(
        w.block === "trigno" // Delsys speaks its protocol: nothing listens at the TCU's port here
          ? /Trigno Control Utility at 127\.0\.0\.1:50040 not reachable: .* --simulate-devices/
          : w.block === "forces" // DLR_ADCBT speaks its protocol: there is no COM7 here
            ? /DLR ADC\/BT: cannot open COM7: .* --simulate-devices/
            : // NilsPod speaks its protocol: there is no Bluetooth adapter here
              /^NilsPod: .* --simulate-devices\)?$/,
      );
    }
    const summary = jsonLines(r.stdout).find((l) => l.type === "summary") as {
      blocks: { name: string; events: number }[];
    };
    expect(summary.blocks.find((b) => b.name === "held")!.events).toBeGreaterThan(20);
  }, 60_000);
});
