/**
 * What the page holds of the pipeline it shows (usePipeline's state) and what a finished load
 * makes of it: pure functions, without React (unit-tested in pipeline-state.test.ts).
 */
import type { Diagnostic } from "../../engine/diagnostics";
import type { GraphInfo } from "../../engine/protocol";
import type { Reply } from "../client/engine-client";

export interface PipelineEntry {
  file: string;
  title: string;
}

export interface PipelineState {
  /** Examples offered by the picker. */
  index: PipelineEntry[];
  /** What the picker shows: the file of what runs, after every load (and while choosing). */
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
  /** The last load that failed while another pipeline kept running (shown beside it). */
  rejected: Rejected | undefined;
}

/** A file that did not load; the pipeline that ran before it goes on. */
export interface Rejected {
  file: string;
  diagnostics: Diagnostic[];
  error: string | undefined;
}

/** The load failed and the pipeline shown before it still runs (or is loaded) in the engine. */
export function keepsRunning(p: PipelineState, r: Reply, kept: boolean): boolean {
  return !r.ok && kept && p.graph !== undefined;
}

/** A problem outside the file's diagnostics (network, engine). */
export function loadError(r: Reply): string | undefined {
  return r.ok || (r.diagnostics ?? []).length > 0 ? undefined : (r.message ?? "cannot load");
}

/**
 * What a finished load leaves: the new pipeline when it loaded; else, when the engine still has
 * the one before (it keeps running what runs), that one with the failure beside it; else the
 * failure alone. `kept`: the engine still has a pipeline after the reply.
 */
export function afterLoad(
  p: PipelineState,
  file: string,
  source: string,
  r: Reply,
  kept: boolean,
): PipelineState {
  const diagnostics = r.diagnostics ?? [];
  const error = loadError(r);
  if (keepsRunning(p, r, kept)) {
    const selected = p.file ?? p.selected;
    return { ...p, loading: false, selected, rejected: { file, diagnostics, error } };
  }
  return {
    ...p,
    loading: false,
    file,
    selected: file,
    source,
    graph: r.graph,
    generation: p.generation + 1,
    diagnostics,
    error,
    rejected: undefined,
  };
}
