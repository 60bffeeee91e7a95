/** React bindings of EngineClient. */
import { useEffect, useRef, useState, createContext, useContext } from "react";
import type { DataMessage, EngineState } from "../../engine/protocol";
import type { Telemetry } from "../../engine/runtime/runtime";
import type { EngineClient } from "./engine-client";

export const EngineContext = createContext<EngineClient | null>(null);

export function useEngine(): EngineClient {
  const c = useContext(EngineContext);
  if (!c) throw new Error("useEngine outside <EngineContext.Provider>");
  return c;
}

/** The latest telemetry (re-renders at the telemetry rate, 20 Hz). */
export function useTelemetry(): Telemetry | undefined {
  const client = useEngine();
  const [t, setT] = useState(client.telemetry);
  useEffect(() => client.onTelemetry(setT), [client]);
  return t;
}

export function useEngineState(): EngineState {
  const client = useEngine();
  const [s, setS] = useState(client.state);
  useEffect(() => client.onState(setS), [client]);
  return s;
}

/**
 * Calls `onData` for every data message of a block output while the component is mounted and
 * `active` (a hidden panel passes false: the engine then stops sending).
 */
export function useBlockData(
  block: string,
  port: string | undefined,
  onData: (m: DataMessage) => void,
  active = true,
  maxRate = 500,
): void {
  const client = useEngine();
  const cb = useRef(onData);
  cb.current = onData;
  useEffect(() => {
    if (!active) return undefined;
    return client.watch(block, port, (m) => cb.current(m), maxRate);
  }, [client, block, port, active, maxRate]);
}
