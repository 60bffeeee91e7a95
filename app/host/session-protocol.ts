/** Messages between the session hub (host main thread) and its session worker. */
import type { Shape } from "../engine/frame";
import type { EngineMessage, UiMessage } from "../engine/protocol";
import type { SabRingInit } from "../engine/runtime/sab-ring";
import type { BleReply, BleRequest } from "../../native-bridges/ble-proxy";
import type { SerialReply, SerialRequest } from "../../native-bridges/serial-proxy";
import type { TimeBase } from "./time-base";

export type HubToSession =
  | {
      type: "session-init";
      wasmPath: string;
      /** Relative pipeline file names ("pipelines/x.yaml" from the UI's list) resolve here. */
      pipelinesDir: string;
      timeBase: TimeBase;
      /** Where session recordings (the UI's Record button) go; else the pipeline's folder. */
      dataDir?: string;
    }
  /**
   * The folders the pipelines loaded from now on may read and write (null: anywhere). The hub
   * sends it before every `load` (loads go one at a time): a client's are confined, the host's own
   * are not.
   */
  | { type: "confine"; dirs: string[] | null }
  | UiMessage
  | SerialReply
  | BleReply;

export type SessionToHub =
  | EngineMessage
  | { type: "session-ready"; doorbell: SharedArrayBuffer }
  | {
      type: "log-open";
      id: number;
      baseDir: string;
      block: string;
      port: string;
      isDefaultPort: boolean;
      path: string;
      shape: Shape;
      ring: SabRingInit;
    }
  | { type: "log-close"; id: number }
  | SerialRequest
  | BleRequest;
