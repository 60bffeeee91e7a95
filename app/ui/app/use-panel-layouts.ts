/**
 * Saves the open panels of the loaded pipeline as they change and, when another pipeline file
 * (or the page) loads, opens the panels saved for it (panel-layouts.ts: localStorage, keyed by
 * the file name). Loading the same file again keeps the panels as they are.
 */
import { useEffect, useRef } from "react";
import type { GraphInfo } from "../../engine/protocol";
import type { OpenPanel } from "./panel-host";
import {
  panelsFor,
  readLayout,
  writeLayout,
  type PanelView,
  type SavedPanel,
} from "./panel-layouts";

function storage(): Storage | undefined {
  try {
    return window.localStorage;
  } catch {
    return undefined;
  }
}

function toSaved(p: OpenPanel, type: string): SavedPanel {
  return {
    name: p.name,
    type,
    floating: p.floating,
    collapsed: p.collapsed,
    x: p.x,
    y: p.y,
    ...(p.width !== undefined && p.height !== undefined
      ? { width: p.width, height: p.height }
      : {}),
    ...(p.view ? { view: p.view } : {}),
  };
}

function toOpen(s: SavedPanel, z: number): OpenPanel {
  const { type: _type, ...rest } = s;
  return { ...rest, z };
}

export function usePanelLayouts(
  graph: GraphInfo | undefined,
  panels: readonly OpenPanel[],
  setPanels: (f: (ps: OpenPanel[]) => OpenPanel[]) => void,
  /** Stable (a ref's function): a new one would not restore anything again. */
  nextZ: () => number,
): void {
  /** The file whose panels are being saved (set when its saved panels were restored). */
  const fileRef = useRef<string | undefined>(undefined);
  /** A restore is on its way: the panels of this render are not the new file's yet. */
  const restoring = useRef(false);

  useEffect(() => {
    if (!graph || fileRef.current === graph.file) return;
    fileRef.current = graph.file;
    restoring.current = true;
    const blocks = new Map(graph.blocks.map((b) => [b.name, b]));
    const saved = panelsFor(readLayout(storage(), graph.file), blocks);
    if (saved.length > 0) setPanels(() => saved.map((s) => toOpen(s, nextZ())));
  }, [graph, setPanels, nextZ]);

  useEffect(() => {
    if (!graph || fileRef.current !== graph.file) return;
    if (restoring.current) {
      restoring.current = false;
      return;
    }
    const types = new Map(graph.blocks.map((b) => [b.name, b.type]));
    const open = panels.filter((p) => types.has(p.name));
    writeLayout(
      storage(),
      graph.file,
      open.map((p) => toSaved(p, types.get(p.name)!)),
    );
  }, [graph, panels]);
}

/**
 * Tells `onView` a panel's view whenever it changes (not on every render): its tab, output and
 * view settings, except a scope's pause (a panel opened again shows live data).
 */
export function useReportView(
  onView: ((v: PanelView) => void) | undefined,
  tab: string,
  port: string | undefined,
  settings: object,
): void {
  const last = useRef("");
  useEffect(() => {
    if (!onView) return;
    const kept: Record<string, Record<string, unknown>> = {};
    for (const [kind, s] of Object.entries(settings as Record<string, object>)) {
      const { paused: _paused, ...rest } = s as Record<string, unknown>;
      kept[kind] = rest;
    }
    const view: PanelView = { tab, ...(port !== undefined ? { port } : {}), settings: kept };
    const text = JSON.stringify(view);
    if (text === last.current) return;
    last.current = text;
    onView(view);
  }, [onView, tab, port, settings]);
}
