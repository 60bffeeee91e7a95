/**
 * `mosaic bench`: the processes it runs beside the workloads — a bare worker that shows what
 * waking up alone costs on this machine (the wake-up floor), the same worker sending a pipeline's
 * datagrams (the floor with its output), and the neighbour that burns a core during the loaded run.
 */
import { spawn, type ChildProcess } from "node:child_process";
import { BenchReceiver, type UdpRxFigures } from "./bench-receiver";
import { clkTck, nsDelta, readStatTicks, readTaskNs } from "./bench-procfs";
import { quantile } from "./bench-stats";
import { sleep } from "./bench-util";

/** How long a floor worker runs before its CPU is sampled (start-up, connecting), ms. */
const SETTLE_MS = 1500;

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
  return medianCpu(spawnWorker(worker), seconds);
}

/** What a pipeline sends: events per second, datagrams per event, and where the bench receives. */
export interface FloorDatagrams {
  eventHz: number;
  perEvent: number;
  port: number;
}

/**
 * The wake-up floor with the pipeline's output: the bare worker of `measureWakeFloor`, waking at
 * `hz`, also sends `perEvent` streamlined datagrams (count 1, f64: 22 bytes, what the
 * ControlAlgorithm → UdpSender of every bench pipeline sends) per event at `eventHz` from a
 * connected node:dgram socket with a completion callback, to a receiver in another process
 * (127.0.0.1:`port`), and turns its event loop every 50 ms, as an engine worker does. What any
 * program that wakes this often and sends this much costs here, before it computes anything.
 * The worker's source is a literal (not a bundled function) because it runs as an eval'd worker.
 */
function ioFloorWorker(hz: number, d: FloorDatagrams): string {
  return `
const dgram = require("node:dgram");
const bell = new Int32Array(new SharedArrayBuffer(4));
const wakeMs = 1000 / ${hz}, eventMs = 1000 / ${d.eventHz}, perEvent = ${d.perEvent};
const socket = dgram.createSocket("udp4");
const buf = Buffer.alloc(22);
const view = new DataView(buf.buffer, buf.byteOffset, buf.length);
let counter = 0;
// A completion callback as the product's bridge has (its cost is part of the floor); a datagram
// lost shows at the receiver as a counter gap.
const afterSend = () => {};
function sendEvent(t) {
  for (let k = 0; k < perEvent; k++) {
    buf[0] = 1; buf[1] = 0x28; buf[2] = 1; buf[3] = k;
    view.setFloat64(4, t, true); view.setFloat64(12, k, true); view.setUint16(20, counter, true);
    counter = (counter + 1) & 0xffff;
    socket.send(buf, afterSend);
  }
}
socket.connect(${d.port}, "127.0.0.1", () => {
  const start = performance.now();
  let wake = 1, event = 1;
  const turn = () => {
    const until = performance.now() + 50;
    while (performance.now() < until) {
      const r = start + wake * wakeMs - performance.now();
      if (r > 0) Atomics.wait(bell, 0, 0, r);
      wake++;
      while (start + event * eventMs <= performance.now()) sendEvent(event++ * eventMs / 1000);
    }
    setImmediate(turn);
  };
  turn();
});`;
}

/**
 * The floor with the pipeline's datagrams (`ioFloorWorker`), % of one core (median of 1-s samples
 * over `seconds`), and what reached the receiver over those seconds (the receiver's figures), so a
 * report shows that they were sent.
 */
export async function measureIoFloor(
  hz: number,
  d: Omit<FloorDatagrams, "port">,
  seconds: number,
): Promise<{ pct: number; udp: UdpRxFigures }> {
  const rx = await BenchReceiver.open(0);
  try {
    const from = performance.now() + SETTLE_MS;
    const pct = await medianCpu(spawnWorker(ioFloorWorker(hz, { ...d, port: rx.port })), seconds);
    return { pct, udp: rx.figures(from, performance.now(), d.eventHz) };
  } finally {
    await rx.close();
  }
}

/** A child process running `source` in one worker thread (its main thread only waits). */
function spawnWorker(source: string): ChildProcess {
  return spawn(
    process.execPath,
    ["-e", `new (require("node:worker_threads").Worker)(${JSON.stringify(source)},{eval:true})`],
    { stdio: "ignore" },
  );
}

/** The child's CPU, % of one core: the median of 1-s samples over `seconds` after 1.5 s; kills it. */
async function medianCpu(child: ChildProcess, seconds: number): Promise<number> {
  const pid = child.pid;
  try {
    if (pid === undefined) return NaN;
    await sleep(SETTLE_MS);
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
