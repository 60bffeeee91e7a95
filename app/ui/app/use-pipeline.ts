/**
 * Loading pipelines: the list of examples (pipelines/index.json of the browser build), fetching a
 * file, sending `load` and, when it loads, `start`. Keeps the file's text for "Save layout" and
 * the diagnostics of a file that does not load.
 */
import { useCallback, useEffect, useRef, useState } from "react";
import type { Diagnostic } from "../../engine/diagnostics";
import type { GraphInfo } from "../../engine/protocol";
import type { EngineClient, Reply } from "../client/engine-client";
import type { LoadReport } from "./log-book";

export interface PipelineEntry {
  file: string;
  title: string;
}

export interface PipelineState {
  /** Examples offered by the picker. */
  index: PipelineEntry[];
  /** What the picker shows. */
  selected: string;
  /** The file being loaded or loaded last. */
  file: string | undefined;
  source: string | undefined;
  graph: GraphInfo | undefined;
  /** Increases with every load (a key for components that start fresh per load). */
  generation: number;
  loading: boolean;
  diagnostics: Diagnostic[];
  /** A problem that is not in the file (network, engine). */
  error: string | undefined;
  /** Load with simulated devices (the toolbar's switch). */
  simulateDevices: boolean;
}

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
  });
  const busy = useRef(0);
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

  /** Loads `file` with `source` (already read) and starts it when it loads. */
  const loadSource = useCallback(
    async (file: string, source: string, autostart = true): Promise<Reply> => {
      const ticket = ++busy.current;
      setS((p) => ({ ...p, loading: true, file, error: undefined }));
      const r = await client.load(file, source, simulate.current);
      if (ticket !== busy.current) return { ok: false, message: "another load started" };
      const diagnostics = r.diagnostics ?? [];
      const error = r.ok || diagnostics.length > 0 ? undefined : (r.message ?? "cannot load");
      report({ file, diagnostics, ...(error !== undefined ? { error } : {}), replaced: true });
      setS((p) => ({
        ...p,
        loading: false,
        file,
        source,
        graph: r.graph,
        generation: p.generation + 1,
        diagnostics,
        error,
      }));
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
        setS((p) => ({ ...p, file, loading: false, error }));
        return { ok: false, message: `cannot read ${file}` };
      }
      return loadSource(file, text, autostart);
    },
    [loadSource, report],
  );

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
        source: undefined,
        graph,
        generation: p.generation + 1,
        diagnostics: [],
        error: undefined,
        simulateDevices: graph.simulateDevices === true,
      }));
    },
    [report],
  );

  // Another client of a shared engine (a tab, the desktop menu) loaded a pipeline: show it.
  useEffect(() => client.onRemoteGraph(adopt), [client, adopt]);

  return { ...s, load, loadSource, select, adopt, setSimulateDevices, onLoadReport };
}
