/**
 * Loading pipelines: the list of examples (pipelines/index.json of the browser build), fetching a
 * file, sending `load` and, when it loads, `start`. Keeps the file's text for "Save layout" and
 * the diagnostics of a file that does not load. The engine keeps what runs when a file does not
 * load: so does the page (named in the picker, the failure shown beside it; issue 17, defect 4).
 */
import { useCallback, useEffect, useRef, useState } from "react";
import type { GraphInfo } from "../../engine/protocol";
import type { EngineClient, Reply } from "../client/engine-client";
import { keptChanges, liveChanges, type LiveChange } from "../editor/live-values";
import type { LoadReport } from "./log-book";
import {
  afterLoad,
  keepsRunning,
  loadError,
  type PipelineEntry,
  type PipelineState,
  type Rejected,
} from "./pipeline-state";

export type { PipelineEntry, PipelineState, Rejected } from "./pipeline-state";

export const DEFAULT_PIPELINE = "pipelines/demo.yaml";

/**
 * `simulateDevices`: the switch's first position (on in the browser build, which has no devices).
 */
export function usePipeline(client: EngineClient, initial: string, simulateDevices = false) {
  const simulate = useRef(simulateDevices);
  const [s, setS] = useState<PipelineState>({
    index: [],
    selected: initial,
    file: undefined,
    source: undefined,
    graph: undefined,
    generation: 0,
    loading: false,
    diagnostics: [],
    error: undefined,
    simulateDevices,
    rejected: undefined,
  });
  const busy = useRef(0);
  // The state as last rendered (a finished load builds on it: see afterLoad).
  const current = useRef(s);
  current.current = s;
  const reportListeners = useRef(new Set<(r: LoadReport) => void>());
  const report = useCallback((r: LoadReport) => {
    for (const l of reportListeners.current) l(r);
  }, []);
  /**
   * What each load reported (diagnostics, a problem outside the file), told synchronously when
   * its reply arrives: before any runtime event of the pipeline it loaded.
   */
  const onLoadReport = useCallback((l: (r: LoadReport) => void) => {
    reportListeners.current.add(l);
    return () => {
      reportListeners.current.delete(l);
    };
  }, []);

  useEffect(() => {
    let cancelled = false;
    fetch("pipelines/index.json")
      .then((r) => (r.ok ? (r.json() as Promise<PipelineEntry[]>) : []))
      .then((index) => {
        if (!cancelled) setS((p) => ({ ...p, index }));
      })
      .catch(() => {
        /* no index: the picker offers the current file only */
      });
    return () => {
      cancelled = true;
    };
  }, []);

  /**
   * Loads `file` with `source` (already read) and starts it when it loads. `keepLive`: the same
   * file loaded again keeps the live values changed since it was loaded (see keptChanges).
   */
  const loadSource = useCallback(
    async (file: string, source: string, autostart = true, keepLive = false): Promise<Reply> => {
      const ticket = ++busy.current;
      const live = keepLive && file === current.current.file ? liveChanges(client.graph) : [];
      setS((p) => ({ ...p, loading: true }));
      const r = await client.load(file, source, simulate.current);
      if (r.ok) await setAgain(client, keptChanges(live, r.graph));
      if (ticket !== busy.current) return { ok: false, message: "another load started" };
      const kept = client.state !== "empty";
      const replaced = !keepsRunning(current.current, r, kept);
      const diagnostics = r.diagnostics ?? [];
      const error = loadError(r);
      report({ file, diagnostics, ...(error !== undefined ? { error } : {}), replaced });
      setS((p) => afterLoad(p, file, source, r, kept));
      if (r.ok && autostart) await client.start();
      return r;
    },
    [client, report],
  );

  /** Fetches a file of the build (relative to the page) and loads it. */
  const load = useCallback(
    async (file: string, autostart = true): Promise<Reply> => {
      setS((p) => ({ ...p, selected: file }));
      let text: string;
      try {
        const r = await fetch(file);
        if (!r.ok) throw new Error(`HTTP ${r.status} ${r.statusText}`.trim());
        text = await r.text();
      } catch (e) {
        const error = `Cannot read ${file}: ${(e as Error).message}`;
        report({ file, diagnostics: [], error, replaced: false });
        setS((p) =>
          p.graph !== undefined
            ? {
                ...p,
                loading: false,
                selected: p.file ?? p.selected,
                rejected: rejectedRead(file, error),
              }
            : { ...p, file, loading: false, error },
        );
        return { ok: false, message: `cannot read ${file}` };
      }
      return loadSource(file, text, autostart);
    },
    [loadSource, report],
  );

  /** Hides the failed load shown beside the running pipeline. */
  const dismissRejected = useCallback(() => setS((p) => ({ ...p, rejected: undefined })), []);

  const select = useCallback((file: string) => setS((p) => ({ ...p, selected: file })), []);

  /** The switch: later loads simulate devices (or not). */
  const setSimulateDevices = useCallback((on: boolean) => {
    simulate.current = on;
    setS((p) => ({ ...p, simulateDevices: on }));
  }, []);

  /** Shows a pipeline the (shared) engine already has, without loading anything. */
  const adopt = useCallback(
    (graph: GraphInfo) => {
      busy.current++;
      simulate.current = graph.simulateDevices === true;
      report({ file: graph.file, diagnostics: [], adopted: true, replaced: true });
      setS((p) => ({
        ...p,
        loading: false,
        file: graph.file,
        selected: graph.file,
        // The engine's copy of the text (Save layout, edit mode, writing live values back).
        source: graph.source,
        graph,
        generation: p.generation + 1,
        diagnostics: [],
        error: undefined,
        rejected: undefined,
        simulateDevices: graph.simulateDevices === true,
      }));
    },
    [report],
  );

  // Another client of a shared engine (a tab, the desktop menu) loaded a pipeline: show it.
  useEffect(() => client.onRemoteGraph(adopt), [client, adopt]);
  // A client wrote the live values back: the pipeline's text is the new one.
  useEffect(
    () =>
      client.onParams((_blocks, source) => {
        if (source !== undefined) setS((p) => (p.graph === client.graph ? { ...p, source } : p));
      }),
    [client],
  );

  return {
    ...s,
    load,
    loadSource,
    select,
    adopt,
    setSimulateDevices,
    onLoadReport,
    dismissRejected,
  };
}

/** Sets live values in the engine again (after the pipeline was loaded again). */
async function setAgain(client: EngineClient, changes: LiveChange[]): Promise<void> {
  for (const c of changes) await client.setParam(c.block, c.param, c.value);
}

function rejectedRead(file: string, error: string): Rejected {
  return { file, diagnostics: [], error };
}
