/**
 * `mosaic bench`: the command line — help, durations, the workloads `--only` selects.
 */
import { parseArgs } from "node:util";
import { out } from "./bench-util";
import { selects, WORKLOADS, type WorkloadDef } from "./bench-workloads";

const HELP = `mosaic bench — the standard performance suite (DESIGN.md §6, paper section V)

Usage:
  mosaic bench [--duration S] [--warmup S] [--only NAME[,NAME]] [--out DIR] [--quick]

Runs each workload as a child \`mosaic run … --json\` and measures it from outside (CPU and RSS
from /proc every second; ΔT statistics, delivery delay and status shares from the run's
telemetry; the pipelines' UDP output with a receiver in this process). Prints Markdown tables
and writes DIR/latest.json and DIR/latest.md (default DIR: bench/results).

  --duration S  steady-state seconds per pipeline after the warm-up (default 30; the timer
                workloads and every run of the batching sweep use half, at least 2)
  --warmup S    seconds excluded at the start of each real-time run (default 25, as the paper;
                the batching sweep uses at most 15)
  --only LIST   run only these workloads: ${workloadIds()}
                (an id selects that workload; replay, or NAME* as in 'timer*', selects a
                group); learn is the micro-benchmark of the learning kernels (ns per update
                and prediction); batching runs Delsys and Myo at --batching-ms 0, 1, 2, 5, 10
  --out DIR     where to write latest.json and latest.md
  --quick       a smoke test: 1 s warm-up, 3 s steady state, short replays (about 40 s in all)

soak (only with --only soak, not in the suite) runs the Delsys pipeline with the Python sidecar
and a UDP sender for 30 minutes after the warm-up (--duration S instead; --quick: 3 s) and
checks that VmRSS stays within 5 %, that every datagram sent arrived or was counted as not sent,
and that every error was counted.

Exit 0 when every selected workload ran (missed targets are reported, not an error), 1 when one
failed to run, 2 on bad options.
`;

/**
 * Seconds excluded at the start of every real-time run, as the paper excluded 25 s: at 25–200 Hz
 * V8 keeps compiling hot functions for tens of seconds (a run of the Myo pipeline measured, in 5-s
 * windows after start, 4.3 %, 2.6 %, 2.5 %, 1.9 % … settling near 1.6–1.8 % after 25 s).
 */
const DEFAULT_WARMUP_S = 25;

export interface BenchOptions {
  quick: boolean;
  /** Steady-state seconds per pipeline (whole seconds, at least 1). */
  steady: number;
  /** Warm-up seconds per real-time run. */
  warmup: number;
  /** `--only` as given. */
  only: string | undefined;
  /** `--out` as given. */
  out: string | undefined;
  /** `--duration` was given (the soak's own length applies otherwise). */
  durationGiven: boolean;
  selected: WorkloadDef[];
}

/** The options, or the exit code when there is nothing to run (help, bad options). */
export function parseBenchOptions(argv: string[]): BenchOptions | { exit: number } {
  let values;
  try {
    values = parseFlags(argv);
  } catch (e) {
    process.stderr.write(`mosaic bench: ${(e as Error).message}\n${HELP}`);
    return { exit: 2 };
  }
  if (values.help) {
    out(HELP);
    return { exit: 0 };
  }
  const quick = values.quick;
  let steady: number;
  let warmup: number;
  try {
    steady = Math.max(1, Math.floor(positive("duration", values.duration, quick ? 3 : 30)));
    warmup = positive("warmup", values.warmup, quick ? 1 : DEFAULT_WARMUP_S, true);
  } catch (e) {
    process.stderr.write(`mosaic bench: ${(e as Error).message}\n`);
    return { exit: 2 };
  }
  const selected =
    values.only !== undefined
      ? selectWorkloads(values.only)
      : WORKLOADS.filter((w) => !("explicit" in w && w.explicit));
  if (!selected) return { exit: 2 };
  return {
    quick,
    steady,
    warmup,
    only: values.only,
    out: values.out,
    durationGiven: values.duration !== undefined,
    selected,
  };
}

function parseFlags(argv: string[]) {
  return parseArgs({
    args: argv,
    allowPositionals: false,
    options: {
      duration: { type: "string" },
      warmup: { type: "string" },
      only: { type: "string" },
      out: { type: "string" },
      quick: { type: "boolean", default: false },
      help: { type: "boolean", short: "h", default: false },
    },
  }).values;
}

/** `--NAME v` as a positive (or non-negative) number of seconds; `dflt` when not given. */
function positive(name: string, v: string | undefined, dflt: number, allowZero = false): number {
  if (v === undefined) return dflt;
  const n = Number(v);
  if (!(allowZero ? n >= 0 : n > 0) || !Number.isFinite(n)) {
    throw new Error(
      `--${name} must be a ${allowZero ? "non-negative" : "positive"} number of seconds, not '${v}'`,
    );
  }
  return n;
}

/** The workloads `--only LIST` selects, in the suite's order; undefined (after saying why) when
 * a name selects none or the list is empty. */
function selectWorkloads(only: string): WorkloadDef[] | undefined {
  const names = only
    .split(",")
    .map((s) => s.trim())
    .filter(Boolean);
  const unknown = names.filter((n) => !WORKLOADS.some((w) => selects(n, w.id)));
  if (unknown.length || names.length === 0) {
    process.stderr.write(
      `mosaic bench: unknown workload ${unknown.map((n) => `'${n}'`).join(", ") || "(none given)"}; ` +
        `workloads: ${workloadIds()}\n`,
    );
    return undefined;
  }
  return WORKLOADS.filter((w) => names.some((n) => selects(n, w.id)));
}

function workloadIds(): string {
  return WORKLOADS.map((w) => w.id).join(", ");
}
