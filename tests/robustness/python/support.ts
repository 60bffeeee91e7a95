/**
 * Shared by tests/robustness/python-*.test.ts: the real CLI with real sidecar processes (the uv
 * environment of native-bridges/python), a work folder with the fixture module, telemetry from
 * `--json`, and the process table (which processes carry a run's marker in their environment).
 */
import { spawn, spawnSync, type ChildProcess } from "node:child_process";
import { copyFileSync, readdirSync, readFileSync } from "node:fs";
import { join } from "node:path";
import { CLI, jsonLines, ROOT, tempDir } from "../../integration/helpers";

export { jsonLines, requireBuild, runCli } from "../../integration/helpers";

const FIXTURES = join(ROOT, "tests", "robustness", "python");

/** True where the sidecar's uv environment works (scripts/setup.sh); the tests skip otherwise. */
export const havePython =
  process.platform === "linux" &&
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

/** A temp folder holding robust_funcs.py. */
export function workdir(): string {
  const dir = tempDir("mosaic-robust-py-");
  copyFileSync(join(FIXTURES, "robust_funcs.py"), join(dir, "robust_funcs.py"));
  return dir;
}

export interface BlockTel {
  name: string;
  status: string;
  rate: number;
  events: number;
  stumbling: boolean;
  lagging: boolean;
  text: string;
  errors: number;
  lastError: string;
}

export const telemetry = (stdout: string): { blocks: BlockTel[] }[] =>
  jsonLines(stdout).filter((l) => l.type === "telemetry") as unknown as { blocks: BlockTel[] }[];

export const blockEvents = (stdout: string, block: string): string[] =>
  jsonLines(stdout)
    .filter((l) => l.type === "event" && l.block === block)
    .map((l) => `${String(l.level)}: ${String(l.message)}`);

export const summaryOf = (stdout: string): { exitCode: number; blocks: BlockTel[] } =>
  jsonLines(stdout).find((l) => l.type === "summary") as unknown as {
    exitCode: number;
    blocks: BlockTel[];
  };

/** A unique value for MOSAIC_TEST_MARK: every process a run starts inherits it. */
export const newMarker = (): string => `robust-${process.pid}-${Date.now()}-${Math.random()}`;

/** Pids of the live processes whose environment holds `MOSAIC_TEST_MARK=marker`. */
export function markedPids(marker: string): number[] {
  const needle = Buffer.from(`MOSAIC_TEST_MARK=${marker}\0`);
  const pids: number[] = [];
  for (const name of readdirSync("/proc")) {
    if (!/^\d+$/.test(name)) continue;
    try {
      const env = readFileSync(`/proc/${name}/environ`);
      // A zombie (exited, not yet reaped) has an empty environment: it is gone.
      if (env.includes(needle)) pids.push(Number(name));
    } catch {
      // gone meanwhile, or not ours
    }
  }
  return pids;
}

/** Waits until no process carries `marker` (true), or `ms` passed (false). */
export async function noneLeft(marker: string, ms: number): Promise<boolean> {
  const t0 = Date.now();
  while (Date.now() - t0 < ms) {
    if (markedPids(marker).length === 0) return true;
    await sleep(50);
  }
  return markedPids(marker).length === 0;
}

/** Kills whatever a failed test left behind (by pid), so the machine stays clean. */
export function killMarked(marker: string): void {
  for (const pid of markedPids(marker)) {
    try {
      process.kill(pid, "SIGKILL");
    } catch {
      // gone
    }
  }
}

/** A process's command line, for messages. */
export function commandLine(pid: number): string {
  try {
    return readFileSync(`/proc/${pid}/cmdline`, "utf8").split("\0").join(" ").trim();
  } catch {
    return "?";
  }
}

/** Field `nice` of /proc/PID/stat. */
export function niceOf(pid: number): number {
  const stat = readFileSync(`/proc/${pid}/stat`, "utf8");
  return Number(stat.slice(stat.lastIndexOf(")") + 2).split(" ")[16]);
}

export const sleep = (ms: number): Promise<void> => new Promise((r) => setTimeout(r, ms));

export interface Cli {
  child: ChildProcess;
  stdout: () => string;
  stderr: () => string;
  exited: Promise<{ code: number | null; signal: NodeJS.Signals | null }>;
}

/** `mosaic run ARGS` in its own process group, with `marker` in its environment. */
export function startRun(args: string[], cwd: string, marker: string): Cli {
  const child = spawn(process.execPath, [CLI, "run", ...args], {
    cwd,
    env: { ...process.env, NO_COLOR: "1", MOSAIC_TEST_MARK: marker },
    detached: true,
  });
  let out = "";
  let err = "";
  child.stdout.on("data", (d: Buffer) => (out += d.toString()));
  child.stderr.on("data", (d: Buffer) => (err += d.toString()));
  const exited = new Promise<{ code: number | null; signal: NodeJS.Signals | null }>((r) =>
    child.on("exit", (code, signal) => r({ code, signal })),
  );
  return { child, stdout: () => out, stderr: () => err, exited };
}

/** Waits for `cond`, polling every 25 ms; throws after `ms`, or when `cli` ended first. */
export async function until(
  cond: () => boolean,
  ms: number,
  what: string,
  cli?: Cli,
): Promise<void> {
  const t0 = Date.now();
  while (!cond()) {
    if (Date.now() - t0 > ms) throw new Error(`timed out waiting for ${what}`);
    const c = cli?.child;
    if (c && (c.exitCode !== null || c.signalCode !== null)) {
      throw new Error(
        `the run ended before ${what}:\n${cli.stderr()}\n${cli.stdout().slice(-2000)}`,
      );
    }
    await sleep(25);
  }
}
