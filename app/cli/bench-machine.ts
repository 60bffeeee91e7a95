/**
 * `mosaic bench`: where the product is (dist/cli.mjs, the repository) and what it runs on (Node,
 * CPU, memory, kernel, the git commit), for the header of the results.
 */
import { execFileSync } from "node:child_process";
import { existsSync, readFileSync } from "node:fs";
import { cpus, release, totalmem } from "node:os";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";
import { clkTck } from "./bench-procfs";
import { loadAvg, round } from "./bench-util";

export interface Machine {
  node: string;
  platform: string;
  cpuModel: string;
  cores: number;
  memoryGiB: number;
  clkTck: number;
  /** Where the CPU figures come from. */
  cpuSource: string;
  /** Load average before and after the suite. */
  loadAvgBefore: number[];
  loadAvgAfter: number[];
  gitCommit: string | null;
  /** Whether the tree had uncommitted changes (null: unknown). */
  gitDirty: boolean | null;
}

/**
 * dist/cli.mjs: beside this bundle or one folder up (the bench is a chunk the CLI loads on
 * demand, dist/chunks/), else the repository's dist.
 */
export function findCli(): string {
  const here = fileURLToPath(import.meta.url);
  if (here.endsWith(".mjs")) {
    const near = [dirname(here), dirname(dirname(here))].map((d) => join(d, "cli.mjs"));
    return near.find((f) => existsSync(f)) ?? near[0]!;
  }
  return join(findRoot(dirname(here)), "dist", "cli.mjs");
}

/** The repository root above `from` (package.json and pipelines/), else the working directory. */
export function findRoot(from: string): string {
  let d = from;
  for (let i = 0; i < 8; i++) {
    if (existsSync(join(d, "package.json")) && existsSync(join(d, "pipelines"))) return d;
    const up = dirname(d);
    if (up === d) break;
    d = up;
  }
  return process.cwd();
}

/** The machine now (`loadAvgAfter` is filled in when the suite ends). */
export function machineInfo(root: string, useNs: boolean): Machine {
  return {
    node: process.version,
    platform: `${process.platform} ${release()}`,
    cpuModel: cpuModel(),
    cores: cpus().length,
    memoryGiB: round(totalmem() / 2 ** 30, 1),
    clkTck: clkTck(),
    cpuSource: useNs
      ? "sum of /proc/<pid>/task/*/schedstat (ns)"
      : `/proc/<pid>/stat utime+stime (${clkTck()} ticks/s)`,
    loadAvgBefore: loadAvg(),
    loadAvgAfter: [],
    gitCommit: git(root, ["rev-parse", "HEAD"]),
    gitDirty: gitDirty(root),
  };
}

function cpuModel(): string {
  try {
    const m = /^model name\s*:\s*(.+)$/m.exec(readFileSync("/proc/cpuinfo", "utf8"));
    if (m) return m[1]!.trim();
  } catch {
    // not Linux
  }
  return cpus()[0]?.model ?? "unknown";
}

function git(root: string, args: string[]): string | null {
  try {
    return execFileSync("git", args, {
      cwd: root,
      encoding: "utf8",
      stdio: ["ignore", "pipe", "ignore"],
    }).trim();
  } catch {
    return null;
  }
}

function gitDirty(root: string): boolean | null {
  const s = git(root, ["status", "--porcelain"]);
  return s === null ? null : s.length > 0;
}
