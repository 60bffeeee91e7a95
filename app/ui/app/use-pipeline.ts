/**
 * Loading pipelines: the list of examples (pipelines/index.json of the browser build), fetching a
 * file, sending `load` and, when it loads, `start`. Keeps the file's text for "Save layout" and
 * the diagnostics of a file that does not load. The engine keeps what runs when a file does not
 * load: so does the page (named in the picker, the failure shown beside it; issue 17, defect 4).
 */
import { useCallback, useRef, useState } from "react";
import type { EngineClient } from "../client/engine-client";
import type { PipelineState } from "./pipeline-state";
import { usePipelineIndex } from "./use-pipeline-index";
import { useLoadFile, useLoadSource } from "./use-pipeline-load";
import { useAdopt, useRemoteChanges } from "./use-pipeline-remote";
import { useLoadReports } from "./use-pipeline-reports";

export type { PipelineEntry, PipelineState, Rejected } from "./pipeline-state";

export const DEFAULT_PIPELINE = "pipelines/demo.yaml";

/**
 * `simulateDevices`: the switch's first position (on in the browser build, which has no devices).
 * Returns the state with its actions: `load` (a file of the build), `loadSource` (a text already
 * read), `select`, `adopt`, `setSimulateDevices`, `onLoadReport` and `dismissRejected`.
 */
export function usePipeline(client: EngineClient, initial: string, simulateDevices = false) {
  const simulate = useRef(simulateDevices);
  const [s, setS] = useState<PipelineState>(() => emptyState(initial, simulateDevices));
  const busy = useRef(0);
  // The state as last rendered (a finished load builds on it: see afterLoad).
  const current = useRef(s);
  current.current = s;
  const { report, onLoadReport } = useLoadReports();
  usePipelineIndex(setS);
  const loadSource = useLoadSource({ client, setS, busy, current, simulate, report });
  const load = useLoadFile(setS, report, loadSource);

  /** Hides the failed load shown beside the running pipeline. */
  const dismissRejected = useCallback(() => setS((p) => ({ ...p, rejected: undefined })), []);

  const select = useCallback((file: string) => setS((p) => ({ ...p, selected: file })), []);

  /** The switch: later loads simulate devices (or not). */
  const setSimulateDevices = useCallback((on: boolean) => {
    simulate.current = on;
    setS((p) => ({ ...p, simulateDevices: on }));
  }, []);

  const adopt = useAdopt(busy, simulate, setS, report);
  useRemoteChanges(client, adopt, setS);

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

/** Nothing loaded yet: `initial` selected. */
function emptyState(initial: string, simulateDevices: boolean): PipelineState {
  return {
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
  };
}
