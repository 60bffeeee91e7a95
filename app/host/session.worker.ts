/**
 * The engine behind `mosaic serve` and the desktop app: one EngineSession (the UI protocol) in a
 * Node worker thread, with the real-time loop, the native I/O bridges and `Path` logs written by
 * the host's main thread. The main thread (app/host/session-hub.ts) relays the protocol to its
 * clients (WebSocket tabs, the Electron window) and runs what cannot run in a worker (serial).
 */
import { readFileSync } from "node:fs";
import { dirname, isAbsolute, resolve } from "node:path";
import { parentPort } from "node:worker_threads";
import { catalog } from "../blocks/catalog";
import { MonotonicClock } from "../engine/clock";
import { errorMessage } from "../engine/diagnostics";
import { initDsp } from "../engine/dsp";
import type { Frame, Shape } from "../engine/frame";
import type { LogChannel, LogSink } from "../engine/runtime/logsink";
import { RealtimeLoop } from "../engine/runtime/loop";
import type { Runtime } from "../engine/runtime/runtime";
import { SabRing } from "../engine/runtime/sab-ring";
import { EngineSession, type LoopHooks } from "../engine/session";
import { bleProxy } from "../../native-bridges/ble-proxy";
import { nodeRosBridge } from "../../native-bridges/ros";
import { serialProxy } from "../../native-bridges/serial-proxy";
import { nodeUdpBridge } from "../../native-bridges/udp";
import { createPythonBridge } from "../../native-bridges/python";
import { nodeResources } from "./resources";
import { clockFromBase } from "./time-base";
import type { HubToSession, SessionToHub } from "./session-protocol";

const port = parentPort;
if (!port) throw new Error("session.worker must run in a worker thread");
const post = (m: SessionToHub, transfer?: ArrayBuffer[]): void =>
  port.postMessage(m, transfer ?? []);

let session: EngineSession | undefined;
let pipelinesDir = process.cwd();
const pending: unknown[] = [];
const doorbell = new Int32Array(new SharedArrayBuffer(8));
let loop: RealtimeLoop | undefined;
const serial = serialProxy((m) => post(m));
const ble = bleProxy((m) => post(m));

/** Where a pipeline's relative paths (data, logs) start: its folder. */
function folderOf(file: string): string {
  return dirname(isAbsolute(file) ? file : resolve(pipelinesDir, file));
}

let nextLog = 0;
function logSink(file: string): LogSink {
  const baseDir = folderOf(file);
  return {
    open(block: string, portName: string, isDefaultPort: boolean, path: string, shape: Shape) {
      const id = nextLog++;
      const stride = shape.rows * shape.cols;
      const capacity = Math.max(4096, Math.ceil((1 << 17) / (stride + 1)));
      const init = SabRing.allocate(capacity, stride);
      const ring = new SabRing(init);
      post({
        type: "log-open",
        id,
        baseDir,
        block,
        port: portName,
        isDefaultPort,
        path,
        shape,
        ring: init,
      });
      const channel: LogChannel = {
        write(f: Frame) {
          ring.write(f, false);
        },
        close() {
          ring.close();
          post({ type: "log-close", id });
        },
      };
      return channel;
    },
  };
}

const yieldNow = (fn: () => void): void => void setImmediate(fn);

function startLoop(rt: Runtime, hooks: LoopHooks) {
  loop = new RealtimeLoop({
    runtime: rt,
    yieldNow,
    clock: rt.clock,
    doorbell,
    precision: false,
    ...hooks,
  });
  loop.start();
  return loop;
}

function boot(msg: Extract<HubToSession, { type: "session-init" }>): void {
  pipelinesDir = msg.pipelinesDir;
  initDsp(readFileSync(msg.wasmPath));
  session = new EngineSession(catalog, {
    engine: "node host",
    sharedMemory: true,
    clock: () => clockFromBase(msg.timeBase) as MonotonicClock,
    resources: (file) => nodeResources(folderOf(file)),
    logs: (file) => logSink(file),
    io: {
      udp: nodeUdpBridge(),
      ros: nodeRosBridge(),
      serial: serial.bridge,
      ble: ble.bridge,
      python: createPythonBridge(),
    },
    startLoop,
    post: (m, transfer) => post(m, transfer),
  });
  post({ type: "session-ready", doorbell: doorbell.buffer as SharedArrayBuffer });
  for (const m of pending.splice(0)) void session.handle(m);
}

port.on("message", (msg: HubToSession) => {
  try {
    if (msg.type === "session-init") boot(msg);
    else if (msg.type === "serial") serial.receive(msg);
    else if (msg.type === "ble") ble.receive(msg);
    else if (session) void session.handle(msg);
    else pending.push(msg);
    // The loop turns the event loop only when rung or every 50 ms: answer at once.
    loop?.wake();
  } catch (e) {
    post({
      type: "event",
      event: { t: Date.now() / 1000, level: "error", block: "engine", message: errorMessage(e) },
    });
  }
});
