/**
 * Latency of a sensor frame through a pipeline to a device (DESIGN.md §6: "sensor frame in → UDP
 * datagram out, same worker", target p99 ≤ 1 ms). The real host runs
 *
 *     Rx (UdpReceiver) → Abs (Function abs) → Tx (UdpSender)
 *
 * in one engine worker, optionally next to a timer branch (Timer → EmgSimulator → Function →
 * Sink) that gives the worker's loop the deadlines of a normal pipeline. This process plays the
 * sensor and the device with one loopback socket: it sends streamlined datagrams to Rx at a steady
 * rate, each carrying its sequence number as value 0, and times each one until the datagram that
 * Tx sends for it arrives. The figure is therefore the whole loop (two kernel loopback hops, the
 * worker waking, the pipeline, the send): an upper bound of in → out. `mosaic bench` runs it with
 * a batching interval of 0 (`batchingMs`: the timer branch wakes the worker for every tick, as
 * DESIGN.md §6 states the target); a datagram wakes the I/O worker at once whatever the interval.
 *
 * Run on its own:
 *   node scripts/build-ts.mjs && node_modules/.bin/esbuild app/cli/bench-udp.ts --bundle \
 *     --platform=node --format=esm --outfile=dist/bench-udp.mjs && node dist/bench-udp.mjs [--json]
 */
import { createSocket, type Socket } from "node:dgram";
import { mkdtempSync, rmSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { Host } from "../host/host";

export interface UdpLatencyOptions {
  /** Datagrams timed after the warm-up (default 3000). */
  samples?: number;
  /** Datagrams per second sent to the receiver (default 500). */
  rate?: number;
  /** Values per datagram (default 8, f64). */
  channels?: number;
  /** Seconds of traffic before timing starts (default 1). */
  warmup?: number;
  /** Rate of the timer branch on the same worker, 0 for none (default 200 Hz). */
  timerHz?: number;
  /** The host's precision mode (spins the last ~0.3 ms before each tick). */
  precision?: boolean;
  /** The batching interval of the timer branch, ms (`mosaic run --batching-ms`; default: the
   * engine's default). */
  batchingMs?: number;
  workerPath?: string;
  wasmPath?: string;
}

export interface UdpLatencyResult {
  samples: number;
  received: number;
  lost: number;
  rate: number;
  channels: number;
  timerHz: number;
  /** The batching interval the host ran with, ms (NaN: the engine's default). */
  batchingMs: number;
  p50Ms: number;
  p90Ms: number;
  p99Ms: number;
  maxMs: number;
  meanMs: number;
  /**
   * The two halves, split at the receiver's callback (its arrival timestamp travels back in the
   * sender's datagram; all threads share one clock): in = socket → worker awake → Rx callback,
   * out = Rx callback → pipeline → send → measuring socket.
   */
  inP50Ms: number;
  inP99Ms: number;
  outP50Ms: number;
  outP99Ms: number;
}

const HEADER = 12;

/** A streamlined f64 datagram (docs/protocols.md) whose value 0 is `seq`. */
function datagram(seq: number, channels: number, t: number): Buffer {
  // A new buffer each time: dgram may still hold the previous one when the next is written.
  const buf = Buffer.alloc(HEADER + 8 * channels + 2);
  buf[0] = channels;
  buf[1] = 0x28;
  buf[2] = 0;
  buf[3] = 0;
  buf.writeDoubleLE(t, 4);
  buf.writeDoubleLE(seq, HEADER);
  for (let i = 1; i < channels; i++) buf.writeDoubleLE(Math.sin(seq + i), HEADER + 8 * i);
  buf.writeUInt16LE(seq & 0xffff, HEADER + 8 * channels);
  return buf;
}

async function bindLoopback(socket: Socket): Promise<number> {
  await new Promise<void>((res, rej) => {
    socket.once("error", rej);
    socket.bind(0, "127.0.0.1", () => {
      socket.off("error", rej);
      res();
    });
  });
  return socket.address().port;
}

async function freePort(): Promise<number> {
  const s = createSocket("udp4");
  const port = await bindLoopback(s);
  await new Promise<void>((r) => s.close(() => r()));
  return port;
}

function quantileMs(sorted: Float64Array, q: number): number {
  if (sorted.length === 0) return NaN;
  const i = Math.min(sorted.length - 1, Math.max(0, Math.ceil(q * sorted.length) - 1));
  return sorted[i]!;
}

const sleep = (ms: number): Promise<void> => new Promise((r) => setTimeout(r, ms));

/** Runs the loop described above and returns the latency quantiles (milliseconds). */
export async function measureUdpLatency(opts: UdpLatencyOptions = {}): Promise<UdpLatencyResult> {
  const samples = opts.samples ?? 3000;
  const rate = opts.rate ?? 500;
  const channels = opts.channels ?? 8;
  const warmup = opts.warmup ?? 1;
  const timerHz = opts.timerHz ?? 200;
  if (!(channels >= 1 && channels <= 255)) throw new Error("channels must be 1 to 255");

  // Touch `performance` before the host takes its time base: its first use loads perf_hooks
  // (1–3 ms), which would otherwise shift the host's clock against ours by that much.
  performance.now();
  const probe = createSocket("udp4");
  const outPort = await bindLoopback(probe);
  const inPort = await freePort();
  const dir = mkdtempSync(join(tmpdir(), "mosaic-bench-udp-"));
  const file = join(dir, "udp-latency.yaml");
  writeFileSync(file, latencyPipeline(inPort, outPort, channels, timerHz));

  const trips = new RoundTrips(samples + Math.ceil(warmup * rate));
  probe.on("message", (msg) => trips.onReply(msg, performance.now()));
  const send = (seq: number): void => {
    trips.sentAt[seq] = performance.now();
    probe.send(datagram(seq, channels, Date.now() / 1000), inPort, "127.0.0.1");
  };
  const failure = { fatal: "" };
  const loaded = await Host.load(file, hostOptions(opts), { fatal: (m) => (failure.fatal = m) });
  if (!loaded.host) {
    probe.close();
    rmSync(dir, { recursive: true, force: true });
    throw new Error(
      `the latency pipeline did not load: ${loaded.diagnostics.map((d) => d.message).join("; ")}`,
    );
  }
  const host = loaded.host;
  try {
    host.start();
    await waitForAnswer(trips, send, failure);
    await sleep(50);
    trips.reset();
    await steadyTraffic(trips.total, rate, send, failure);
    await sleep(200);
  } finally {
    await host.stop();
    probe.close();
    rmSync(dir, { recursive: true, force: true });
  }
  return latencyResult(trips, {
    samples,
    rate,
    channels,
    timerHz,
    batchingMs: opts.batchingMs ?? NaN,
  });
}

/** Rx → Abs → Tx, and the timer branch that gives the worker a normal pipeline's deadlines. */
function latencyPipeline(
  inPort: number,
  outPort: number,
  channels: number,
  timerHz: number,
): string {
  return [
    `Rx: { Type: UdpReceiver, Params: { Port: ${inPort}, Channels: ${channels} } }`,
    "Abs: { Type: Function, Inputs: [Rx], Params: { Operation: abs } }",
    `Tx: { Type: UdpSender, Inputs: [Abs], Params: { Port: ${outPort} } }`,
    ...(timerHz > 0
      ? [
          `Timer: { Type: ScheduledTimer, DesiredRate: ${timerHz} }`,
          "Emg: { Type: EmgSimulator, Inputs: [Timer], Params: { Channels: 8 } }",
          "Rect: { Type: Function, Inputs: [Emg], Params: { Operation: abs } }",
          "Out: { Type: Sink, Inputs: [Rect] }",
        ]
      : []),
    "",
  ].join("\n");
}

function hostOptions(opts: UdpLatencyOptions): Parameters<typeof Host.load>[1] {
  return {
    mode: "realtime",
    precision: opts.precision ?? false,
    ...(opts.batchingMs !== undefined ? { batchingS: opts.batchingMs / 1000 } : {}),
    ...(opts.workerPath ? { workerPath: opts.workerPath } : {}),
    ...(opts.wasmPath ? { wasmPath: opts.wasmPath } : {}),
  };
}

/** The round trips of one measurement, by sequence number (NaN: not sent, or no reply yet). */
class RoundTrips {
  readonly total: number;
  readonly sentAt: Float64Array;
  /** Sending → the sender's datagram back, ms. */
  readonly latency: Float64Array;
  /** Sending → the receiver's callback, ms. */
  readonly inPart: Float64Array;
  received = 0;

  constructor(total: number) {
    this.total = total;
    this.sentAt = new Float64Array(total).fill(NaN);
    this.latency = new Float64Array(total).fill(NaN);
    this.inPart = new Float64Array(total).fill(NaN);
  }

  /** The sender's datagram `msg` arrived at `now`: its sequence number is value 0. */
  onReply(msg: Buffer, now: number): void {
    if (msg.length < HEADER + 8) return;
    const seq = msg.readDoubleLE(HEADER);
    if (!(seq >= 0 && seq < this.total) || !Number.isInteger(seq)) return;
    if (Number.isNaN(this.latency[seq]!)) {
      this.latency[seq] = now - this.sentAt[seq]!;
      // Tx writes the event's timestamp: the time Rx got the datagram.
      this.inPart[seq] = msg.readDoubleLE(4) * 1000 - (performance.timeOrigin + this.sentAt[seq]!);
      this.received++;
    }
  }

  /** Forget the probes before the timed traffic. */
  reset(): void {
    this.latency.fill(NaN);
    this.inPart.fill(NaN);
    this.received = 0;
  }
}

/** Wait until the receiver listens: a datagram makes the round trip (probes use seq 0). */
async function waitForAnswer(
  trips: RoundTrips,
  send: (seq: number) => void,
  failure: { fatal: string },
): Promise<void> {
  const readyBy = performance.now() + 10_000;
  while (trips.received === 0) {
    if (failure.fatal) throw new Error(failure.fatal);
    if (performance.now() > readyBy) throw new Error("the pipeline did not answer within 10 s");
    send(0);
    await sleep(20);
  }
}

/**
 * Steady traffic, paced by timers (no spinning: the machine may have two cores only); each
 * datagram is timed from when it was actually sent, so pacing jitter does not count.
 */
async function steadyTraffic(
  total: number,
  rate: number,
  send: (seq: number) => void,
  failure: { fatal: string },
): Promise<void> {
  const period = 1000 / rate;
  const t0 = performance.now();
  let next = 0;
  while (next < total) {
    const due = t0 + next * period;
    const now = performance.now();
    if (now < due) await sleep(Math.max(0, Math.round(due - now)));
    send(next);
    next++;
    if (failure.fatal) throw new Error(failure.fatal);
  }
}

/** The quantiles of the last `samples` round trips (the warm-up's left out). */
function latencyResult(
  trips: RoundTrips,
  o: Pick<UdpLatencyResult, "samples" | "rate" | "channels" | "timerHz" | "batchingMs">,
): UdpLatencyResult {
  const { latency, inPart, total } = trips;
  const { samples, rate, channels, timerHz, batchingMs } = o;
  const first = total - samples;
  const timed = latency.subarray(first).filter((x) => !Number.isNaN(x));
  timed.sort();
  // The pipeline clock is this process's monotonic clock mapped to wall time by the host, so
  // performance.timeOrigin + performance.now() reads the same clock here.
  const ins: number[] = [];
  const outs: number[] = [];
  for (let i = first; i < total; i++) {
    if (Number.isNaN(latency[i]!)) continue;
    ins.push(inPart[i]!);
    outs.push(latency[i]! - inPart[i]!);
  }
  const insSorted = Float64Array.from(ins).sort();
  const outsSorted = Float64Array.from(outs).sort();
  let sum = 0;
  for (const x of timed) sum += x;
  return {
    samples,
    received: timed.length,
    lost: samples - timed.length,
    rate,
    channels,
    timerHz,
    batchingMs,
    p50Ms: quantileMs(timed, 0.5),
    p90Ms: quantileMs(timed, 0.9),
    p99Ms: quantileMs(timed, 0.99),
    maxMs: timed.length > 0 ? timed[timed.length - 1]! : NaN,
    meanMs: timed.length > 0 ? sum / timed.length : NaN,
    inP50Ms: quantileMs(insSorted, 0.5),
    inP99Ms: quantileMs(insSorted, 0.99),
    outP50Ms: quantileMs(outsSorted, 0.5),
    outP99Ms: quantileMs(outsSorted, 0.99),
  };
}

/** One Markdown line for a result. */
export function udpLatencyLine(r: UdpLatencyResult): string {
  const f = (x: number) => x.toFixed(3);
  return (
    `UDP in → pipeline → UDP out (${r.channels} ch f64 @ ${r.rate} Hz, timer branch ` +
    `${r.timerHz > 0 ? `${r.timerHz} Hz` : "none"}${Number.isFinite(r.batchingMs) ? `, batching interval ${r.batchingMs} ms` : ""}): p50 ${f(r.p50Ms)} ms, p90 ${f(r.p90Ms)} ms, ` +
    `p99 ${f(r.p99Ms)} ms, max ${f(r.maxMs)} ms (${r.received}/${r.samples} timed, ${r.lost} lost; ` +
    `target p99 ≤ 1 ms); in → Rx callback p50 ${f(r.inP50Ms)} / p99 ${f(r.inP99Ms)} ms, ` +
    `Rx callback → out p50 ${f(r.outP50Ms)} / p99 ${f(r.outP99Ms)} ms`
  );
}

// Run directly: node dist/bench-udp.mjs [--json] [--samples N] [--rate HZ] [--timer HZ]
//   [--batching-ms MS]
const invoked = process.argv[1] ?? "";
if (/bench-udp\.(mjs|js|ts)$/.test(invoked)) {
  const arg = (name: string): number | undefined => {
    const i = process.argv.indexOf(`--${name}`);
    return i > 0 ? Number(process.argv[i + 1]) : undefined;
  };
  const samples = arg("samples");
  const rate = arg("rate");
  const timerHz = arg("timer");
  const channels = arg("channels");
  const batchingMs = arg("batching-ms");
  measureUdpLatency({
    ...(samples !== undefined ? { samples } : {}),
    ...(rate !== undefined ? { rate } : {}),
    ...(timerHz !== undefined ? { timerHz } : {}),
    ...(channels !== undefined ? { channels } : {}),
    ...(batchingMs !== undefined ? { batchingMs } : {}),
    precision: process.argv.includes("--precision"),
  }).then(
    (r) => {
      console.log(process.argv.includes("--json") ? JSON.stringify(r) : udpLatencyLine(r));
    },
    (e: unknown) => {
      console.error(`bench-udp: ${e instanceof Error ? e.message : String(e)}`);
      process.exitCode = 1;
    },
  );
}
