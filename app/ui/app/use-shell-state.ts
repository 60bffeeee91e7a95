/**
 * The app shell's smaller hooks: the loaded pipeline as the shell sees it, reduced motion, the
 * actions of blocks and gesture keys, editing a param that is not live, node positions kept
 * across reloads, the first load, the window's title and the toolbar's pipeline controls.
 */
import { useCallback, useEffect, useRef, useState } from "react";
import type { EngineState } from "../../engine/protocol";
import type { EngineClient } from "../client/engine-client";
import { setBlockParam } from "../graph/layout-yaml";
import { useGestureKeys } from "./gestures";
import type { LogEntry } from "./log-book";
import type { EditStatic } from "./panel-host";
import { shortName } from "./pipeline-picker";
import type { Notify } from "./use-notice";
import type { usePipeline } from "./use-pipeline";
import { useWriteLiveValues } from "./use-live-values";

/** What usePipeline gives: the pipeline's state and the ways to load one. */
export type Pipeline = ReturnType<typeof usePipeline>;

/** A ref that always holds the value of the last render. */
export function useLatest<T>(value: T): { readonly current: T } {
  const ref = useRef(value);
  ref.current = value;
  return ref;
}

export function useReducedMotion(): boolean {
  const q = "(prefers-reduced-motion: reduce)";
  const [r, setR] = useState(() => window.matchMedia?.(q).matches ?? false);
  useEffect(() => {
    const m = window.matchMedia?.(q);
    if (!m) return undefined;
    const on = (): void => setR(m.matches);
    m.addEventListener("change", on);
    return () => m.removeEventListener("change", on);
  }, []);
  return r;
}

/** "Write live values…" into the text of the pipeline the page holds. */
export function usePipelineLiveValues(
  client: EngineClient,
  pipeline: Pipeline,
  notify: Notify,
): () => void {
  return useWriteLiveValues(
    client,
    () =>
      pipeline.file !== undefined && pipeline.source !== undefined
        ? { file: pipeline.file, source: pipeline.source }
        : undefined,
    notify,
  );
}

/** A block's action (its reply noticed) and the gesture keys of simulated EMG (logged). */
export function useBlockActions(
  client: EngineClient,
  graph: Pipeline["graph"],
  notify: Notify,
  addLog: (e: Omit<LogEntry, "id">) => void,
) {
  const invoke = useCallback(
    (block: string, action: string, arg: unknown, label: string) => {
      void client.invoke(block, action, arg).then((r) => {
        notify(
          r.message ?? (r.ok ? `${label}: done` : `${label}: failed`),
          r.ok ? "info" : "error",
          block,
        );
      });
    },
    [client, notify],
  );
  const onGesture = useCallback(
    (message: string, ok: boolean, block: string) => {
      if (!ok) notify(message, "error", block);
      else addLog({ t: Date.now() / 1000, level: "info", block, message });
    },
    [notify, addLog],
  );
  useGestureKeys(client, graph, onGesture);
  return { invoke, onGesture };
}

/**
 * A param that is not live, changed while stopped: edit the file's text and load it again
 * (the old text comes back when the new one does not load). "Save layout…" downloads it.
 */
export function useEditStatic(
  client: EngineClient,
  pipeline: Pipeline,
  notify: Notify,
): EditStatic {
  const current = useLatest(pipeline);
  return useCallback<EditStatic>(
    async (block, param, value) => {
      const { file, source } = current.current;
      if (file === undefined || source === undefined)
        return { ok: false, message: "no pipeline file" };
      if (client.state === "running") return { ok: false, message: "stop the pipeline first" };
      let text: string;
      try {
        text = setBlockParam(source, block, param, value);
      } catch (e) {
        return { ok: false, message: (e as Error).message };
      }
      const r = await current.current.loadSource(file, text, false, true);
      if (r.ok) {
        notify(
          `${param} = ${JSON.stringify(value)}: pipeline reloaded (Start to run it)`,
          "info",
          block,
        );
        return { ok: true, message: "reloaded with the new value" };
      }
      const why =
        r.diagnostics?.find((d) => d.severity === "error")?.message ?? r.message ?? "failed";
      await current.current.loadSource(file, source, false, true);
      return { ok: false, message: why };
    },
    [client, notify],
  );
}

/** Node positions survive reloading the same file (a param edit, Load again). */
export function useLayoutMemory(file: string | undefined): Map<string, { x: number; y: number }> {
  const layoutMemory = useRef<{
    file: string | undefined;
    positions: Map<string, { x: number; y: number }>;
  }>({
    file: undefined,
    positions: new Map(),
  });
  if (layoutMemory.current.file !== file) {
    layoutMemory.current = { file, positions: new Map() };
  }
  return layoutMemory.current.positions;
}

/** Loads the first pipeline, or shows the one a shared engine already runs. */
export function useFirstLoad(
  client: EngineClient,
  pipeline: Pipeline,
  initialPipeline: string,
  sharedEngine: boolean,
): void {
  const started = useRef(false);
  useEffect(() => {
    if (started.current) return;
    started.current = true;
    if (!sharedEngine) {
      void pipeline.load(initialPipeline);
      return;
    }
    // A shared engine (mosaic serve, the desktop app) may already run a pipeline: its first
    // state message (after hello and the graph, if any) tells. Show that one; else load ours.
    const off = client.onState((st) => {
      off();
      if (st !== "empty" && client.graph) pipeline.adopt(client.graph);
      else void pipeline.load(initialPipeline);
    });
  }, [pipeline, initialPipeline, sharedEngine, client]);
}

/** The window's title names what the engine has (the header's picker does too). */
export function useDocumentTitle(pipeline: Pipeline): void {
  const { file, graph } = pipeline;
  useEffect(() => {
    const name = file !== undefined && graph !== undefined ? shortName(file) : "";
    document.title = name ? `${name} — MOSAIC` : "MOSAIC — live pipeline";
  }, [file, graph]);
}

/** The toolbar's picker (the URL names the file picked) and Start (a finished run reloads). */
export function usePipelineControls(
  client: EngineClient,
  pipeline: Pipeline,
  state: EngineState,
): { selectPipeline(file: string): void; start(): void } {
  const selectPipeline = (file: string): void => {
    pipeline.select(file);
    const url = new URL(window.location.href);
    url.searchParams.set("pipeline", file);
    window.history.replaceState(null, "", url);
  };
  const start = (): void => {
    if (state === "finished" && pipeline.file !== undefined && pipeline.source !== undefined) {
      void pipeline.loadSource(pipeline.file, pipeline.source, true, true);
    } else void client.start();
  };
  return { selectPipeline, start };
}
