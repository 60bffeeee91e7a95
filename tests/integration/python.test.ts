/**
 * The Python block with a real sidecar process (native-bridges/python, run through uv), through
 * the real CLI: values round-trip bit for bit; a function slower than its budget marks only its
 * own branch; `kill -9` of the sidecar mid-run is survived and reported; a syntax error in the
 * user module is a load error naming the block, the file and the line. Skipped where uv or the
 * sidecar's environment is missing (scripts/setup.sh installs them).
 */
import { spawnSync } from "node:child_process";
import { copyFileSync, readFileSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { describe, expect, test } from "vitest";
import { jsonLines, KEEPING_UP, requireBuild, ROOT, runCli, startCli, tempDir } from "./helpers";

const FIXTURES = join(ROOT, "tests", "integration", "python");

const havePython =
  spawnSync(
    "python3",
    [
      "-m",
      "uv",
      "run",
      "--quiet",
      "--frozen",
      "--project",
      join(ROOT, "native-bridges", "python"),
      "--python",
      "python3.11",
      "python",
      "-c",
      "import numpy",
    ],
    { env: { ...process.env, UV_PYTHON_DOWNLOADS: "never" }, timeout: 120_000 },
  ).status === 0;

interface BlockTel {
  name: string;
  status: string;
  rate: number;
  events: number;
  stumbling: boolean;
  lagging: boolean;
  text: string;
  errors: number;
}

const telemetry = (stdout: string): { blocks: BlockTel[] }[] =>
  jsonLines(stdout).filter((l) => l.type === "telemetry") as unknown as { blocks: BlockTel[] }[];

/** A temp folder with the fixture modules. */
function workdir(): string {
  const dir = tempDir("mosaic-python-");
  for (const f of ["fixture_funcs.py", "broken_syntax.py"]) {
    copyFileSync(join(FIXTURES, f), join(dir, f));
  }
  return dir;
}

/** Log lines by timestamp. */
function logByTime(path: string): Map<string, string> {
  const m = new Map<string, string>();
  for (const line of readFileSync(path, "utf8").split("\n")) {
    if (!line) continue;
    const comma = line.indexOf(",");
    m.set(line.slice(0, comma), line.slice(comma + 1));
  }
  return m;
}

describe.skipIf(!havePython)("Python block with a real sidecar", () => {
  test("values round-trip bit for bit (±0, subnormals, NaN, ±inf, extremes)", () => {
    requireBuild();
    const dir = workdir();
    const rows = [
      "0,0,-0,5e-324,-5e-324",
      "1,NaN,inf,-inf,1.7976931348623157e+308",
      "2,2.2250738585072014e-308,2.225073858507201e-308,0.30000000000000004,-1e-300",
      "3,3.141592653589793,-2.718281828459045,123456789.12345679,1e-320",
    ];
    writeFileSync(join(dir, "special.csv"), "t,a,b,c,d\n" + rows.join("\n") + "\n");
    // Both Bits blocks return the raw bit patterns (two exact u32 halves per value): one of the
    // recording itself, one of what came back from the identity call.
    writeFileSync(
      join(dir, "roundtrip.yaml"),
      `
Timer: { Type: ScheduledTimer, DesiredRate: 50 }
Src: { Type: FilePlayer, Inputs: [Timer], Params: { File: special.csv, Loop: true } }
Same: { Type: Python, Inputs: [Src], Params: { Module: fixture_funcs.py, Function: identity } }
Direct: { Type: Python, Inputs: [Src], Params: { Module: fixture_funcs.py, Function: bits }, Path: direct.txt }
Back: { Type: Python, Inputs: [Same], Params: { Module: fixture_funcs.py, Function: bits }, Path: back.txt }
`,
    );
    const r = runCli(["run", join(dir, "roundtrip.yaml"), "--duration", "3", "--json"], {
      timeoutMs: 90_000,
    });
    expect(r.code, r.stderr).toBe(0);
    const direct = logByTime(join(dir, "direct.txt"));
    const back = logByTime(join(dir, "back.txt"));
    expect(back.size).toBeGreaterThan(60);
    let compared = 0;
    for (const [t, v] of back) {
      const d = direct.get(t);
      if (d === undefined) continue;
      expect(v, `event at ${t}`).toBe(d);
      compared++;
    }
    expect(compared).toBeGreaterThan(60);
    // The four rows all came through (a -0 keeps its sign bit: 0x80000000 high word).
    const values = new Set(back.values());
    expect(values.size).toBe(4);
    expect([...values].some((v) => v.includes(`,0,${0x80000000}`))).toBe(true);
  }, 120_000);

  test("a call beyond its budget marks only its own branch; the independent branch stays on time", () => {
    requireBuild();
    const dir = workdir();
    // Slow sleeps 60 ms per call at 60 Hz: it runs at ~16 Hz (lagging), and so does its
    // consumer. Tight sleeps 30 ms at 20 Hz against a 20 ms budget: its rate holds, every call is
    // over budget (stumbling). Rectify does not depend on either and stays on time.
    writeFileSync(
      join(dir, "slow.yaml"),
      `
Timer: { Type: ScheduledTimer, DesiredRate: 60 }
Emg: { Type: EmgSimulator, Inputs: [Timer], Params: { Channels: 2 } }
Rectify: { Type: Function, Inputs: [Emg], Params: { Operation: abs } }
Slow: { Type: Python, Inputs: [Emg], Params: { Module: fixture_funcs.py, Function: sleepy, Init: init, Params: { seconds: 0.06 } } }
After: { Type: Function, Inputs: [Slow], Params: { Operation: abs } }
Pace: { Type: DecimatorTimer, DesiredRate: 20, Inputs: [Timer] }
Held: { Type: Resampler, Inputs: [Emg, Pace] }
Tight: { Type: Python, Inputs: [Held], Params: { Module: fixture_funcs.py, Function: sleepy, Init: init, Params: { seconds: 0.03 }, Budget: 20 } }
`,
    );
    const r = runCli(["run", join(dir, "slow.yaml"), "--duration", "6", "--json"], {
      timeoutMs: 90_000,
    });
    expect(r.code, r.stderr).toBe(0);
    const tel = telemetry(r.stdout);
    const late = tel.slice(Math.floor(tel.length / 2));
    const share = (name: string, s: string) =>
      late.filter((t) => t.blocks.find((b) => b.name === name)?.status === s).length / late.length;
    expect(share("Rectify", "ontime")).toBeGreaterThan(0.95);
    expect(share("Emg", "ontime")).toBeGreaterThan(0.95);
    expect(share("Slow", "lagging")).toBeGreaterThan(0.9);
    expect(share("After", "lagging")).toBeGreaterThan(0.9);
    expect(share("Tight", "stumbling")).toBeGreaterThan(0.9);
    const last = Object.fromEntries(tel.at(-1)!.blocks.map((b) => [b.name, b]));
    expect(last.Slow!.stumbling).toBe(true);
    expect(last.Slow!.rate).toBeLessThan(20);
    expect(last.Slow!.text).toMatch(/p50 6\d(\.\d)? ms/);
    expect(last.Slow!.text).toMatch(/[1-9]\d* over budget \(16\.7 ms\)/);
    expect(last.Slow!.text).toMatch(/[1-9]\d* skipped/);
    expect(last.Tight!.text).toMatch(/[1-9]\d* over budget \(20\.0 ms\)/);
    expect(last.Tight!.rate).toBeGreaterThan(19);
  }, 120_000);

  test("kill -9 of the sidecar mid-run: reported, restarted, the block resumes", async () => {
    requireBuild();
    const dir = workdir();
    writeFileSync(
      join(dir, "kill.yaml"),
      `
Timer: { Type: ScheduledTimer, DesiredRate: 50 }
Emg: { Type: EmgSimulator, Inputs: [Timer], Params: { Channels: 2 } }
Py: { Type: Python, Inputs: [Emg], Params: { Module: fixture_funcs.py, Function: identity } }
Other: { Type: Function, Inputs: [Emg], Params: { Operation: abs } }
`,
    );
    const cli = startCli(["run", join(dir, "kill.yaml"), "--duration", "9", "--json"], dir);
    let stdout = "";
    let stderr = "";
    cli.stdout!.on("data", (d: Buffer) => (stdout += d.toString()));
    cli.stderr!.on("data", (d: Buffer) => (stderr += d.toString()));
    const pidOf = (): number | undefined => {
      const t = telemetry(stdout).at(-1);
      const m = /pid (\d+)/.exec(t?.blocks.find((b) => b.name === "Py")?.text ?? "");
      return m ? Number(m[1]) : undefined;
    };
    const wait = (ms: number) => new Promise((r) => setTimeout(r, ms));
    let first: number | undefined;
    for (let i = 0; i < 200 && first === undefined; i++) {
      await wait(50);
      const t = telemetry(stdout)
        .at(-1)
        ?.blocks.find((b) => b.name === "Py");
      if (t && t.events > 50) first = pidOf();
    }
    expect(first, stderr).toBeDefined();
    process.kill(first!, "SIGKILL");
    const code = await new Promise<number | null>((r) => cli.on("exit", r));
    // The crash is a block error (issue 14): the run goes on, and exits 1 at the end.
    expect(code, stderr).toBe(1);
    const tel = telemetry(stdout);
    const last = tel.at(-1)!.blocks.find((b) => b.name === "Py")!;
    // Reported (as a warning event and in the status), restarted under a new pid, running again.
    const events = jsonLines(stdout).filter((l) => l.type === "event" && l.block === "Py");
    expect(events.map((e) => String(e.message)).join("\n")).toMatch(
      new RegExp(`pid ${first}\\).*(SIGKILL|code 137).*restarting in 0\\.5 s`),
    );
    expect(events.some((e) => /restarted \(pid \d+\)/.test(String(e.message)))).toBe(true);
    expect(last.text).toMatch(/1 restart\b/);
    expect(pidOf()).not.toBe(first);
    // Running again: on time, or stumbling when a call ran past its budget on a loaded machine.
    expect(["ontime", "stumbling"], last.text).toContain(last.status);
    const other = tel.at(-1)!.blocks.find((b) => b.name === "Other")!;
    expect(KEEPING_UP).toContain(other.status);
    // The Python block kept going after the restart: most of the 9 s were served.
    expect(last.events).toBeGreaterThan(50 * 5);
  }, 120_000);

  test("an exception in the function: traceback reported, last good output held, block keeps running", () => {
    requireBuild();
    const dir = workdir();
    writeFileSync(
      join(dir, "raise.yaml"),
      `
Timer: { Type: ScheduledTimer, DesiredRate: 50 }
Py: { Type: Python, Inputs: [Emg], Params: { Module: fixture_funcs.py, Function: fails_sometimes, Init: init } }
Emg: { Type: EmgSimulator, Inputs: [Timer], Params: { Channels: 1 } }
`,
    );
    const r = runCli(["run", join(dir, "raise.yaml"), "--duration", "3", "--json"], {
      timeoutMs: 90_000,
    });
    // Exceptions are block errors (issue 14): the run goes on, and exits 1 at the end.
    expect(r.code, r.stderr).toBe(1);
    const events = jsonLines(r.stdout).filter((l) => l.type === "event" && l.block === "Py");
    const text = events.map((e) => String(e.message)).join("\n");
    expect(text).toMatch(
      /ValueError: every third call fails \(at .*fixture_funcs\.py:\d+, in fails_sometimes\)/,
    );
    expect(text).toMatch(/Traceback \(most recent call last\)/);
    const last = telemetry(r.stdout)
      .at(-1)!
      .blocks.find((b) => b.name === "Py")!;
    expect(last.text).toMatch(/errors \(last: ValueError: every third call fails/);
    // hold: an output for every input, failed ones included, so the block keeps its rate: on
    // time, or stumbling when a call ran past its budget on a loaded machine — never lagging.
    expect(["ontime", "stumbling"], last.text).toContain(last.status);
    expect(last.rate).toBeGreaterThan(0.95 * 50);
  }, 120_000);

  test("a syntax error in the module is a load error with the block, file and line", () => {
    requireBuild();
    const dir = workdir();
    writeFileSync(
      join(dir, "broken.yaml"),
      `
Timer: { Type: ScheduledTimer, DesiredRate: 50 }
Emg: { Type: EmgSimulator, Inputs: [Timer], Params: { Channels: 2 } }
Model:
  Type: Python
  Inputs: [Emg]
  Params: { Module: broken_syntax.py, Function: predict }
`,
    );
    const r = runCli(["run", join(dir, "broken.yaml"), "--duration", "2"], { timeoutMs: 90_000 });
    expect(r.code).toBe(2);
    const out = r.stdout + r.stderr;
    expect(out).toMatch(
      /broken\.yaml:7:\d+: error: block 'Model' \(Python\): Python: SyntaxError in /,
    );
    expect(out).toMatch(/broken_syntax\.py:5(:\d+)?: /);
    const missing = join(dir, "missing.yaml");
    writeFileSync(
      missing,
      readFileSync(join(dir, "broken.yaml"), "utf8").replace("broken_syntax.py", "nowhere.py"),
    );
    const m = runCli(["run", missing, "--duration", "2"], { timeoutMs: 90_000 });
    expect(m.code).toBe(2);
    expect(m.stdout + m.stderr).toMatch(
      /block 'Model' \(Python\): Python: module file not found: .*nowhere\.py/,
    );
  }, 120_000);
});
