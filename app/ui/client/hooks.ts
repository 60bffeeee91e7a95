/** React bindings of EngineClient. */
import {
  createContext,
  useCallback,
  useContext,
  useEffect,
  useRef,
  useState,
  useSyncExternalStore,
} from "react";
import type { BlockInfo, DataMessage, EngineState, GraphInfo } from "../../engine/protocol";
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

/** What the engine said in `hello`: its name and whether it has shared memory (precise timing). */
export function useEngineInfo(): { connected: boolean; engine: string; sharedMemory: boolean } {
  const client = useEngine();
  const [, bump] = useState(0);
  useEffect(() => client.onHello(() => bump((n) => n + 1)), [client]);
  return {
    connected: client.connected,
    engine: client.engineName,
    sharedMemory: client.sharedMemory,
  };
}

/** The graph of the loaded pipeline (undefined before a load and after a failed one). */
export function useGraph(): GraphInfo | undefined {
  const client = useEngine();
  const [g, setG] = useState(client.graph);
  useEffect(() => client.onGraph(setG), [client]);
  return g;
}

/**
 * `block` as the engine has it now: its live params changed from any client, and the file's
 * values they are compared with (issue 17, defect 1). Re-renders when a `params` message names
 * the block. `block` itself while the engine's graph has no block of that name and type.
 */
export function useLiveBlock<B extends BlockInfo | undefined>(block: B): B {
  const client = useEngine();
  const getSnapshot = useCallback((): B => {
    if (block === undefined) return block;
    const now = client.graph?.blocks.find((b) => b.name === block.name);
    return (now !== undefined && now.type === block.type ? now : block) as B;
  }, [client, block]);
  const subscribe = useCallback(
    (cb: () => void) =>
      client.onParams((blocks) => {
        if (block !== undefined && blocks.some((b) => b.name === block.name)) cb();
      }),
    [client, block],
  );
  return useSyncExternalStore(subscribe, getSnapshot, getSnapshot);
}

/**
 * Holds back changes that need not show at once: while `ms` have not passed since the value
 * last changed, a new value that `urgent` does not call urgent (e.g. a rate that moved by a few
 * hertz) is not shown yet; the next telemetry after that shows it.
 */
export interface TelemetryHold<T> {
  ms: number;
  urgent(shown: T, next: T): boolean;
}

/**
 * A value derived from the latest telemetry: the component re-renders only when `select` gives a
 * result that `isEqual` says differs from the previous one (shallow equality by default), so a
 * node whose label did not change does not render at 20 Hz. With `hold`, numbers that change on
 * every telemetry (rates, compute times) re-render at most every `hold.ms`: text changes cost a
 * style and layout pass of the page each, and numbers changing 20 times a second cannot be read.
 */
export function useTelemetrySelector<T>(
  select: (t: Telemetry | undefined) => T,
  isEqual: (a: T, b: T) => boolean = shallowEqual,
  hold?: TelemetryHold<T>,
): T {
  const client = useEngine();
  const selectRef = useRef(select);
  const cache = useRef<{
    t: Telemetry | undefined;
    fresh: boolean;
    value: T;
    since: number;
  } | null>(null);
  if (selectRef.current !== select) {
    // A new selector (its inputs changed): recompute, keeping the old value if equal.
    selectRef.current = select;
    if (cache.current) cache.current.fresh = false;
  }
  const getSnapshot = useCallback((): T => {
    const t = client.telemetry;
    const c = cache.current;
    if (c && c.fresh && c.t === t) return c.value;
    const next = selectRef.current(t);
    const now = hold ? performance.now() : 0;
    let value = next;
    let since = now;
    if (c && isEqual(c.value, next)) {
      value = c.value;
      since = c.since;
    } else if (c && hold && now - c.since < hold.ms && !hold.urgent(c.value, next)) {
      value = c.value;
      since = c.since;
    }
    cache.current = { t, fresh: true, value, since };
    return value;
    // `isEqual` is read at call time: callers pass a module-level function.
  }, [client]);
  const subscribe = useCallback((cb: () => void) => client.onTelemetry(cb), [client]);
  return useSyncExternalStore(subscribe, getSnapshot, getSnapshot);
}

/** Shallow equality of two plain objects (or identical values). */
export function shallowEqual<T>(a: T, b: T): boolean {
  if (Object.is(a, b)) return true;
  if (typeof a !== "object" || typeof b !== "object" || a === null || b === null) return false;
  const ka = Object.keys(a);
  const kb = Object.keys(b);
  if (ka.length !== kb.length) return false;
  for (const k of ka) {
    if (!Object.is((a as Record<string, unknown>)[k], (b as Record<string, unknown>)[k]))
      return false;
  }
  return true;
}
