import { readdirSync, readFileSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { beforeAll, describe, expect, test } from "vitest";
import { jsonLines, requireBuild, ROOT, runCli, startCli, tempDir } from "./helpers";

beforeAll(requireBuild);

describe("mosaic validate", () => {
  test("every pipeline in pipelines/ is valid", () => {
    const files: string[] = [];
    const walk = (d: string): void => {
      for (const e of readdirSync(d, { withFileTypes: true })) {
        if (e.isDirectory()) walk(join(d, e.name));
        else if (e.name.endsWith(".yaml")) files.push(join(d, e.name));
      }
    };
    walk(join(ROOT, "pipelines"));
    expect(files.length).toBeGreaterThanOrEqual(3);
    const r = runCli(["validate", ...files]);
    expect(r.stderr.split("\n").filter((l) => l.includes(": error:"))).toEqual([]);
    expect(r.code).toBe(0);
  });

  test("an invalid file exits 2 with file:line:col messages", () => {
    const dir = tempDir();
    const f = join(dir, "bad.yaml");
    writeFileSync(
      f,
      "Timer: { Type: ScheduledTimer, DesiredRate: 200 }\nLowPass: { Type: Fliter, Inputs: [Timer] }\n",
    );
    const r = runCli(["validate", f]);
    expect(r.code).toBe(2);
    expect(r.stderr).toContain(
      `${f}:2:18: error: block 'LowPass': unknown block type 'Fliter'; did you mean 'Filter'?`,
    );
  });

  test("errors found when instantiating (a missing file) are positioned too", () => {
    const dir = tempDir();
    const f = join(dir, "nofile.yaml");
    writeFileSync(
      f,
      "T: { Type: ScheduledTimer, DesiredRate: 100 }\nP:\n  Type: FilePlayer\n  Inputs: [T]\n  Params: { File: nope.csv }\n",
    );
    const r = runCli(["validate", f]);
    expect(r.code).toBe(2);
    expect(r.stderr).toMatch(/nofile\.yaml:5:\d+: error: block 'P' \(FilePlayer\): .*nope\.csv/);
  });
});

describe("mosaic run", () => {
  test("the demo runs with every block on time (5 s, real time)", () => {
    const r = runCli(["run", "pipelines/demo.yaml", "--duration", "5", "--json"], {
      timeoutMs: 30_000,
    });
    expect(r.code).toBe(0);
    const lines = jsonLines(r.stdout);
    const summary = lines.find((l) => l.type === "summary") as unknown as {
      reason: string;
      blocks: { name: string; status: string; rate: number; desiredRate: number }[];
    };
    expect(summary.reason).toBe("duration");
    // Every block on time in nearly every report after the first second. This file runs beside
    // other test files on two cores: one stall of a neighbour makes a batch late, and a late batch
    // shows as "lagging" for at least 100 ms, so a single report (the last one, as this test read
    // before) can catch it. A block that is really slow lags in most reports.
    type Report = typeof summary & { t: number };
    const reports = lines.filter((l) => l.type === "telemetry") as unknown as Report[];
    const settled = reports.filter((r) => r.t >= reports[0]!.t + 1);
    expect(settled.length).toBeGreaterThan(50);
    const notOnTime = new Map<string, number>();
    for (const r of settled) {
      for (const b of r.blocks) {
        if (b.status !== "ontime") notOnTime.set(b.name, (notOnTime.get(b.name) ?? 0) + 1);
      }
    }
    const bad = [...notOnTime]
      .filter(([, n]) => n > 0.1 * settled.length)
      .map(([name, n]) => `${name}: not on time in ${n} of ${settled.length} reports`);
    expect(bad).toEqual([]);
    const tel = settled.at(-1)!;
    expect(tel.blocks.length).toBe(9);
  });

  test("a recording plays in its original timing in real time", () => {
    const dir = tempDir();
    const r = runCli(
      [
        "run",
        "pipelines/examples/replay-envelope.yaml",
        "--duration",
        "2",
        "--json",
        "--log-dir",
        dir,
      ],
      { timeoutMs: 30_000 },
    );
    expect(r.code).toBe(0);
    const lines = jsonLines(r.stdout);
    expect(lines.filter((l) => l.type === "telemetry").length).toBeGreaterThan(25);
    const summary = lines.find((l) => l.type === "summary") as unknown as {
      blocks: { name: string; events: number; status: string }[];
    };
    const rec = summary.blocks.find((b) => b.name === "Recording")!;
    // 1000 rows per second of the real recording, from the pipeline's start.
    expect(rec.events).toBeGreaterThan(1500);
    expect(rec.events).toBeLessThan(2100);
  });

  test("Ctrl-C stops cleanly and flushes the logs", async () => {
    const dir = tempDir();
    const f = join(dir, "log.yaml");
    writeFileSync(
      f,
      "Timer: { Type: ScheduledTimer, DesiredRate: 500 }\nSine: { Type: SinGenerator, Inputs: [Timer], Params: { Components: 3 }, Path: rec/ }\n",
    );
    const child = startCli(["run", f, "--json"]);
    let out = "";
    child.stdout!.on("data", (d: Buffer) => (out += d.toString()));
    // Interrupt once it has run for a while (its telemetry says so): a loaded machine may take
    // seconds to start it, so no fixed wait.
    const ranEnough = (): boolean =>
      /"name":"Sine"[^}]*"events":(\d+)/
        .exec(out.slice(out.lastIndexOf('"type":"telemetry"')))
        ?.slice(1)
        .some((n) => Number(n) > 600) ?? false;
    const t0 = Date.now();
    while (!ranEnough() && Date.now() - t0 < 30_000) await new Promise((r) => setTimeout(r, 50));
    child.kill("SIGINT");
    const code = await new Promise<number | null>((r) => child.on("exit", r));
    expect(code).toBe(0);
    const summary = jsonLines(out).find((l) => l.type === "summary") as {
      reason: string;
      blocks: { name: string; events: number }[];
    };
    expect(summary.reason).toBe("interrupted");
    const lines = readFileSync(join(dir, "rec", "Sine.txt"), "utf8").split("\n");
    expect(lines.at(-1)).toBe("");
    const events = summary.blocks.find((b) => b.name === "Sine")!.events;
    expect(lines.length - 1).toBe(events);
    expect(events).toBeGreaterThan(500);
    for (const l of lines.slice(0, -1)) expect(l).toMatch(/^\d+\.\d{6}(,-?[\d.e+-]+){3}$/);
  });

  test("an invalid pipeline is not started and exits 2", () => {
    const dir = tempDir();
    const f = join(dir, "bad.yaml");
    writeFileSync(f, "Timer: { Type: ScheduledTimer }\n");
    const r = runCli(["run", f, "--duration", "1"]);
    expect(r.code).toBe(2);
    expect(r.stderr).toContain(
      "bad.yaml:1:1: error: block 'Timer' (ScheduledTimer) needs a DesiredRate",
    );
  });
});

describe("command-line arguments", () => {
  test("a command's --help prints the usage, exit 0", () => {
    const r = runCli(["run", "--help"]);
    expect(r.code).toBe(0);
    expect(r.stdout).toContain("mosaic format FILE... [--check]");
  });

  test("an unknown option is one line naming it, exit 2, no stack trace", () => {
    const r = runCli(["run", "x.yaml", "--durration", "1"]);
    expect(r.code).toBe(2);
    expect(r.stderr.trim()).toBe("mosaic run: Unknown option '--durration' (see mosaic --help)");
  });
});
