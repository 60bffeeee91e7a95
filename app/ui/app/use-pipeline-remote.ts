/**
 * usePipeline and a shared engine: a pipeline the engine already has (loaded by another client:
 * a tab, the desktop menu) is shown without loading anything, and live values written back by a
 * client give the pipeline its new text.
 */
import { useCallback, useEffect, type Dispatch, type RefObject, type SetStateAction } from "react";
import type { GraphInfo } from "../../engine/protocol";
import type { EngineClient } from "../client/engine-client";
import type { LoadReport } from "./log-book";
import type { PipelineState } from "./pipeline-state";

/** Shows a pipeline the (shared) engine already has, without loading anything. */
export function useAdopt(
  busy: RefObject<number>,
  simulate: RefObject<boolean>,
  setS: Dispatch<SetStateAction<PipelineState>>,
  report: (r: LoadReport) => void,
): (graph: GraphInfo) => void {
  return useCallback(
    (graph: GraphInfo) => {
      busy.current++;
      simulate.current = graph.simulateDevices === true;
      report({ file: graph.file, diagnostics: [], adopted: true, replaced: true });
      setS((p) => adopted(p, graph));
    },
    [report, busy, simulate, setS],
  );
}

function adopted(p: PipelineState, graph: GraphInfo): PipelineState {
  return {
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
  };
}

/** Follows the other clients of the engine (see the file's comment). */
export function useRemoteChanges(
  client: EngineClient,
  adopt: (graph: GraphInfo) => void,
  setS: Dispatch<SetStateAction<PipelineState>>,
): void {
  // Another client of a shared engine (a tab, the desktop menu) loaded a pipeline: show it.
  useEffect(() => client.onRemoteGraph(adopt), [client, adopt]);
  // A client wrote the live values back: the pipeline's text is the new one.
  useEffect(
    () =>
      client.onParams((_blocks, source) => {
        if (source !== undefined) setS((p) => (p.graph === client.graph ? { ...p, source } : p));
      }),
    [client, setS],
  );
}
