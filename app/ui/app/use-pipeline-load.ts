/**
 * usePipeline's loads: a file's text sent with `load` (and `start` when it loads), and a file of
 * the build fetched first. A file that cannot be read keeps what runs (shown as rejected).
 */
import { useCallback, type Dispatch, type RefObject, type SetStateAction } from "react";
import type { EngineClient, Reply } from "../client/engine-client";
import { keptChanges, liveChanges, type LiveChange } from "../editor/live-values";
import type { LoadReport } from "./log-book";
import {
  afterLoad,
  keepsRunning,
  loadError,
  type PipelineState,
  type Rejected,
} from "./pipeline-state";

export interface LoadDeps {
  client: EngineClient;
  setS: Dispatch<SetStateAction<PipelineState>>;
  /** Counts loads (and adoptions): a load that is no longer the last one gives up. */
  busy: RefObject<number>;
  /** The state as last rendered (a finished load builds on it: see afterLoad). */
  current: RefObject<PipelineState>;
  /** Whether loads simulate devices. */
  simulate: RefObject<boolean>;
  report: (r: LoadReport) => void;
}

export type LoadSource = (
  file: string,
  source: string,
  autostart?: boolean,
  keepLive?: boolean,
) => Promise<Reply>;

/**
 * Loads `file` with `source` (already read) and starts it when it loads. `keepLive`: the same
 * file loaded again keeps the live values changed since it was loaded (see keptChanges).
 */
export function useLoadSource({
  client,
  setS,
  busy,
  current,
  simulate,
  report,
}: LoadDeps): LoadSource {
  return useCallback(
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
    [client, report, setS, busy, current, simulate],
  );
}

/** Fetches a file of the build (relative to the page) and loads it. */
export function useLoadFile(
  setS: Dispatch<SetStateAction<PipelineState>>,
  report: (r: LoadReport) => void,
  loadSource: LoadSource,
): (file: string, autostart?: boolean) => Promise<Reply> {
  return useCallback(
    async (file: string, autostart = true): Promise<Reply> => {
      setS((p) => ({ ...p, selected: file }));
      let text: string;
      try {
        text = await readFile(file);
      } catch (e) {
        const error = `Cannot read ${file}: ${(e as Error).message}`;
        report({ file, diagnostics: [], error, replaced: false });
        setS((p) => afterFailedRead(p, file, error));
        return { ok: false, message: `cannot read ${file}` };
      }
      return loadSource(file, text, autostart);
    },
    [loadSource, report, setS],
  );
}

/** The text of a file of the build; throws when it cannot be read. */
async function readFile(file: string): Promise<string> {
  const r = await fetch(file);
  if (!r.ok) throw new Error(`HTTP ${r.status} ${r.statusText}`.trim());
  return await r.text();
}

/** A file not read: what runs stays (the failure shown beside it), or the error is shown. */
function afterFailedRead(p: PipelineState, file: string, error: string): PipelineState {
  return p.graph !== undefined
    ? {
        ...p,
        loading: false,
        selected: p.file ?? p.selected,
        rejected: rejectedRead(file, error),
      }
    : { ...p, file, loading: false, error };
}

/** Sets live values in the engine again (after the pipeline was loaded again). */
async function setAgain(client: EngineClient, changes: LiveChange[]): Promise<void> {
  for (const c of changes) await client.setParam(c.block, c.param, c.value);
}

function rejectedRead(file: string, error: string): Rejected {
  return { file, diagnostics: [], error };
}
