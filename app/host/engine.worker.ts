/**
 * Engine worker (Node worker_threads): runs the blocks placed on it, on the real-time loop or on
 * the virtual clock, and reports telemetry to the host at 20 Hz. The main thread never runs blocks.
 */
import { readFileSync } from "node:fs";
import { dirname } from "node:path";
import { parentPort } from "node:worker_threads";
import { catalog } from "../blocks/catalog";
import { VirtualClock, type Clock } from "../engine/clock";
import type { Diagnostic } from "../engine/diagnostics";
import { initDsp } from "../engine/dsp";
import { errorMessage } from "../engine/diagnostics";
import type { Frame, Shape } from "../engine/frame";
import { loadPipeline } from "../engine/pipeline/loader";
import { withSimulatedDevices } from "../engine/pipeline/simulate";
import type { LogChannel, LogSink } from "../engine/runtime/logsink";
import { Runtime, type Telemetry } from "../engine/runtime/runtime";
import { SabRing } from "../engine/runtime/sab-ring";
import { runVirtual } from "../engine/runtime/virtual";
import { RealtimeLoop } from "../engine/runtime/loop";
import { serialProxy } from "../../native-bridges/serial-proxy";
import { bleProxy } from "../../native-bridges/ble-proxy";
import { nodeRosBridge } from "../../native-bridges/ros";
import { nodeLslBridge } from "../../native-bridges/lsl";
import { nodeTcpBridge } from "../../native-bridges/tcp";
import { nodeUdpBridge } from "../../native-bridges/udp";
import { createPythonBridge } from "../../native-bridges/python";
import { pipelineCatalog } from "../engine/user-blocks";
import { flushWrites, nodeResources } from "./resources";
import { loadBlockModule } from "./user-blocks";
import { clockFromBase } from "./time-base";
import { TelemetryOutbox } from "./telemetry-outbox";
import type { HostToWorker, InitMessage, TelemetryReport, WorkerToHost } from "./worker-protocol";

const port = parentPort;
if (!port) throw new Error("engine.worker must run in a worker thread");

/** Telemetry waits here for its group (see TelemetryOutbox); other messages go at once. */
const outbox = new TelemetryOutbox((reports) =>
  port.postMessage({ type: "telemetry", reports } satisfies WorkerToHost),
);
/** Posts a message to the host, after the telemetry that waits (the host sees them in order). */
const post = (m: WorkerToHost): void => {
  outbox.flush();
  port.postMessage(m);
};

let rt: Runtime | undefined;
let loop: RealtimeLoop | undefined;
let init: InitMessage | undefined;
let vclock: VirtualClock | undefined;
let stopped = false;
const doorbellSab = new SharedArrayBuffer(8);
const doorbell = new Int32Array(doorbellSab);
const logRings: SabRing[] = [];

/** Path logs travel to the host's log writer through one SAB ring each. */
function sabLogSink(virtual: boolean): LogSink {
  let nextId = 0;
  return {
    open(
      block: string,
      portName: string,
      isDefaultPort: boolean,
      path: string,
      shape: Shape,
    ): LogChannel {
      const id = nextId++;
      const stride = shape.rows * shape.cols;
      // About two seconds of data at 2 kHz for small vectors, at least 1 MiB of doubles.
      const capacity = Math.max(4096, Math.ceil((1 << 17) / (stride + 1)));
      const init = SabRing.allocate(capacity, stride);
      const ring = new SabRing(init);
      logRings.push(ring);
      post({ type: "log-open", id, block, port: portName, isDefaultPort, path, shape, ring: init });
      return {
        write(f: Frame) {
          // Real time: a full ring drops and counts (the writer reports it); virtual: wait.
          ring.write(f, virtual);
        },
        close() {
          ring.close();
          post({ type: "log-close", id });
        },
      };
    },
  };
}

async function create(msg: InitMessage): Promise<void> {
  init = msg;
  try {
    initDsp(readFileSync(msg.wasmPath));
  } catch (e) {
    post({
      type: "fatal",
      message: `cannot load the DSP core (${msg.wasmPath}): ${errorMessage(e)}`,
    });
    return;
  }
  // The pipeline's own blocks (`Pipeline: { Blocks }`), loaded in this worker.
  const own = await pipelineCatalog(msg.source, msg.file, catalog, loadBlockModule);
  if (own.diagnostics.some((d) => d.severity === "error")) {
    post({ type: "failed", diagnostics: own.diagnostics });
    return;
  }
  const blocks = own.catalog;
  const loaded = withSimulatedDevices(
    loadPipeline(msg.source, msg.file, blocks),
    blocks,
    msg.simulateDevices,
  );
  if (!loaded.spec) {
    post({ type: "failed", diagnostics: loaded.diagnostics });
    return;
  }
  const virtual = msg.mode === "virtual";
  let clock: Clock;
  if (virtual) {
    vclock = new VirtualClock(msg.virtualStart);
    clock = vclock;
  } else {
    clock = clockFromBase(msg.timeBase);
  }
  const created = await Runtime.create({
    spec: loaded.spec,
    catalog: blocks,
    clock,
    virtual,
    resources: nodeResources(dirname(msg.file)),
    io: {
      udp: nodeUdpBridge(),
      tcp: nodeTcpBridge(),
      ros: nodeRosBridge(),
      serial: serial.bridge,
      ble: ble.bridge,
      python: createPythonBridge(),
      lsl: nodeLslBridge(),
    },
    logs: sabLogSink(virtual),
    worker: msg.worker,
    ...(msg.plan ? { plan: msg.plan } : {}),
    ...(msg.batchingS !== undefined ? { batchingS: msg.batchingS } : {}),
    ignorePlacement: virtual,
  });
  const diagnostics: Diagnostic[] = [...loaded.diagnostics, ...created.diagnostics];
  if (!created.runtime || !created.plan) {
    post({ type: "failed", diagnostics });
    return;
  }
  rt = created.runtime;
  post({ type: "created", plan: created.plan, diagnostics, doorbell: doorbellSab });
}

/** Telemetry with its blocks and edges encoded once, here (see TelemetryReport). */
function report(t: Telemetry): TelemetryReport {
  return {
    t: t.t,
    worker: t.worker,
    blocks: JSON.stringify(t.blocks),
    edges: JSON.stringify(t.edges),
    events: t.events,
    finished: t.finished,
  };
}

function link(msg: Extract<HostToWorker, { type: "link" }>): void {
  if (!rt) return;
  for (const o of msg.outs) {
    const ring = new SabRing(o.ring);
    const bell = new Int32Array(o.bell);
    rt.attachRemoteOut(o.block, o.port, {
      write(f: Frame) {
        const lost = ring.write(f, false);
        Atomics.add(bell, 0, 1);
        Atomics.notify(bell, 0);
        return lost;
      },
    });
  }
  for (const i of msg.ins) rt.attachRemoteIn(i.block, i.index, new SabRing(i.ring));
}

function start(): void {
  if (!rt || !init) return;
  const runtime = rt;
  rt.start();
  const telemetryIntervalS = 1 / init.telemetryHz;
  outbox.group = init.telemetryGroup;
  if (init.mode === "virtual") {
    const clock = vclock!;
    const until = init.virtualStart + init.virtualDuration;
    let lastTel = performance.now();
    const chunk = (): void => {
      if (stopped) return;
      const r = runVirtual(runtime, clock, until, 20);
      if (performance.now() - lastTel >= telemetryIntervalS * 1000) {
        lastTel = performance.now();
        outbox.add(report(runtime.telemetry()));
      }
      if (r === "yield") setImmediate(chunk);
      else if (r === "waiting") {
        // A block waits for results from outside (Python calls): go on when they are in.
        runtime.onWake = () => {
          runtime.onWake = null;
          setImmediate(chunk);
        };
      } else post({ type: "finished", telemetry: runtime.telemetry() });
    };
    setImmediate(chunk);
    return;
  }
  loop = new RealtimeLoop({
    runtime,
    yieldNow: setImmediate,
    clock: rt.clock,
    doorbell,
    precision: init.precision,
    telemetryIntervalS,
    onTelemetry: (at) => outbox.add(report(runtime.telemetry(at))),
    onFinished: () => post({ type: "finished", telemetry: runtime.telemetry() }),
  });
  rt.onWake = () => loop?.wake();
  loop.start();
}

function stop(): void {
  if (stopped) return;
  stopped = true;
  loop?.stop();
  if (rt) {
    rt.stop();
    rt.dispatch();
    const telemetry = rt.telemetry();
    rt.dispose();
    // Files the blocks are still writing (a model saved at the end) land before the host ends us.
    void flushWrites().then(() => post({ type: "stopped", telemetry }));
  } else {
    post({
      type: "stopped",
      telemetry: {
        t: 0,
        worker: init?.worker ?? "main",
        blocks: [],
        edges: [],
        events: [],
        finished: false,
      },
    });
  }
}

/** Serial ports are opened by the host's main thread (see native-bridges/serial-proxy.ts). */
const serial = serialProxy((m) => post(m));
/** Bluetooth LE runs on the host's main thread too (see native-bridges/ble-proxy.ts). */
const ble = bleProxy((m) => post(m));

port.on("message", (msg: HostToWorker) => {
  try {
    switch (msg.type) {
      case "serial":
        serial.receive(msg);
        break;
      case "ble":
        ble.receive(msg);
        break;
      case "init":
        void create(msg).catch((e: unknown) => post({ type: "fatal", message: errorMessage(e) }));
        break;
      case "link":
        link(msg);
        break;
      case "start":
        start();
        break;
      case "stop":
        stop();
        break;
      case "control": {
        if (!rt) {
          post({ type: "reply", id: msg.id, ok: false, message: "the pipeline is not running" });
          break;
        }
        try {
          let message = "";
          if (msg.op === "invoke") message = rt.invoke(msg.block, msg.action, msg.arg);
          else if (msg.op === "setParam") message = rt.setParam(msg.block, msg.param, msg.value);
          else {
            rt.resetTiming();
            message = "timing statistics reset";
          }
          post({ type: "reply", id: msg.id, ok: true, message });
        } catch (e) {
          post({ type: "reply", id: msg.id, ok: false, message: errorMessage(e) });
        }
        loop?.wake();
        break;
      }
    }
  } catch (e) {
    post({ type: "fatal", message: errorMessage(e) });
  }
});
