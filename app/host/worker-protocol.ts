/** Messages between the host (main thread) and its engine workers. */
import type { Diagnostic } from "../engine/diagnostics";
import type { SimulateOptions } from "../engine/pipeline/simulate";
import type { Shape } from "../engine/frame";
import type { Plan, RuntimeEvent, Telemetry } from "../engine/runtime/runtime";
import type { SabRingInit } from "../engine/runtime/sab-ring";
import type { SerialReply, SerialRequest } from "../../native-bridges/serial-proxy";
import type { BleReply, BleRequest } from "../../native-bridges/ble-proxy";
import type { TimeBase } from "./time-base";

export type ClockMode = "realtime" | "virtual";

/** Telemetry per second when none is asked for (`mosaic run`, the Host): the UI's rate. */
export const DEFAULT_TELEMETRY_HZ = 20;

export interface InitMessage {
  type: "init";
  file: string;
  source: string;
  worker: string;
  mode: ClockMode;
  timeBase: TimeBase;
  /** Virtual clock start, UNIX seconds. */
  virtualStart: number;
  /** Virtual clock: stop at start + duration (Infinity = until sources finish). */
  virtualDuration: number;
  wasmPath: string;
  plan?: Plan;
  precision: boolean;
  telemetryHz: number;
  /**
   * Telemetry reports per message to the host (1: each at once). See TelemetryOutbox: the CLI
   * sends a quarter second's at a time, and its thread wakes 4 times a second instead of 20.
   */
  telemetryGroup: number;
  /** Batching interval for blocks without their own `BatchingMs`, s (the CLI's --batching-ms). */
  batchingS?: number;
  /** Replace device blocks by simulators (`mosaic run --simulate-devices`); undefined: off. */
  simulateDevices?: SimulateOptions;
}

/**
 * Periodic telemetry with its blocks and edges as JSON text: the worker encodes it once, and the
 * host prints it (`mosaic run --json`) or parses it only when someone needs the objects. Cheaper
 * than a structured clone of the object graph decoded on the main thread 20 times a second.
 */
export interface TelemetryReport {
  t: number;
  worker: string;
  /** JSON of `Telemetry.blocks`. */
  blocks: string;
  /** JSON of `Telemetry.edges`. */
  edges: string;
  events: RuntimeEvent[];
  finished: boolean;
}

export interface LinkMessage {
  type: "link";
  outs: { block: string; port: string; ring: SabRingInit; bell: SharedArrayBuffer }[];
  ins: { block: string; index: number; ring: SabRingInit }[];
}

export type ControlOp =
  | { op: "invoke"; block: string; action: string; arg?: unknown }
  | { op: "setParam"; block: string; param: string; value: unknown }
  | { op: "resetTiming" };

export type HostToWorker =
  | InitMessage
  | LinkMessage
  | { type: "start" }
  | { type: "stop" }
  | ({ type: "control"; id: number } & ControlOp)
  | SerialReply
  | BleReply;

export type WorkerToHost =
  | { type: "created"; plan: Plan; diagnostics: Diagnostic[]; doorbell: SharedArrayBuffer }
  | { type: "failed"; diagnostics: Diagnostic[] }
  | {
      type: "log-open";
      id: number;
      block: string;
      port: string;
      isDefaultPort: boolean;
      path: string;
      shape: Shape;
      ring: SabRingInit;
    }
  | { type: "log-close"; id: number }
  | { type: "telemetry"; reports: TelemetryReport[] }
  | { type: "reply"; id: number; ok: boolean; message: string }
  | { type: "finished"; telemetry: Telemetry }
  | { type: "stopped"; telemetry: Telemetry }
  | { type: "fatal"; message: string }
  | SerialRequest
  | BleRequest;
