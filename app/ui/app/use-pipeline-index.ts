/** The list of examples for usePipeline: pipelines/index.json of the browser build. */
import { useEffect, type Dispatch, type SetStateAction } from "react";
import type { PipelineEntry, PipelineState } from "./pipeline-state";

/** Fetches the list once and puts it in the state's `index`. */
export function usePipelineIndex(setS: Dispatch<SetStateAction<PipelineState>>): void {
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
  }, [setS]);
}
