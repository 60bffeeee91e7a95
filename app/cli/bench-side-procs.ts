/**
 * `mosaic bench`: the processes it runs beside the workloads — a bare worker that shows what
 * waking up alone costs on this machine (the wake-up floor), and the neighbour that burns a core
 * during the loaded run.
 */
import { spawn } from "node:child_process";
import { clkTck, nsDelta, readStatTicks, readTaskNs } from "./bench-procfs";
import { quantile } from "./bench-stats";
import { sleep } from "./bench-util";

/**
 * How often a worker wakes for a timer of `hz` ticks per second with a batching interval of
 * `batchingMs` (DESIGN.md §3): it wakes at the deadline of the last tick within the interval of the
 * oldest pending one, i.e. once per floor(interval · hz) + 1 ticks.
 */
export function wakeRate(hz: number, batchingMs: number): number {
  if (!(batchingMs > 0)) return hz;
  return hz / (Math.floor((batchingMs / 1000) * hz + 1e-9) + 1);
}

/**
 * The cost of waking up alone on this machine: a bare Node worker that does nothing but sleep in
 * `Atomics.wait` until each deadline at `hz` (no engine, no event-loop turns), as % of one core
 * (median of 1-s samples over `seconds`). Pipelines cannot go below this at the same wake-up rate
 * (`wakeRate`).
 */
export async function measureWakeFloor(hz: number, seconds: number): Promise<number> {
  const worker =
    "const b=new Int32Array(new SharedArrayBuffer(4));const p=1000/" +
    String(hz) +
    ";const s=performance.now();let k=1;for(;;){const r=s+k*p-performance.now();if(r>0)Atomics.wait(b,0,0,r);k++;}";
  const child = spawn(
    process.execPath,
    ["-e", `new (require("node:worker_threads").Worker)(${JSON.stringify(worker)},{eval:true})`],
    { stdio: "ignore" },
  );
  const pid = child.pid;
  try {
    if (pid === undefined) return NaN;
    await sleep(1500);
    const samples: number[] = [];
    let prev = readTaskNs(pid);
    for (let i = 0; i < seconds; i++) {
      await sleep(1000);
      const cur = readTaskNs(pid);
      const d = nsDelta(prev, cur);
      if (Number.isFinite(d)) samples.push(d / 1e7);
      prev = cur;
    }
    return quantile(samples, 0.5);
  } finally {
    child.kill("SIGKILL");
  }
}

/**
 * A neighbour that burns one core at normal priority (`node -e "for(;;){}"`), for the loaded
 * variant of a workload. `stop()` kills it and returns the CPU it used, % of one core over its life
 * (from /proc/<pid>/stat; NaN when unreadable), so a report shows that it really ran.
 */
export function startNeighbour(): { command: string; stop: () => number } {
  const code = "for(;;){}";
  const child = spawn(process.execPath, ["-e", code], { stdio: "ignore" });
  const t0 = performance.now();
  const pid = child.pid;
  return {
    command: `node -e "${code}"`,
    stop(): number {
      const ticks = pid !== undefined ? readStatTicks(pid) : NaN;
      const seconds = (performance.now() - t0) / 1000;
      child.kill("SIGKILL");
      return seconds > 0 ? (ticks / clkTck() / seconds) * 100 : NaN;
    },
  };
}
