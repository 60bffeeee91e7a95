/**
 * The shell's control panels (docked or floating, stacked by z) and the Stimulus block shown
 * full screen, with the actions any part of the UI may ask for (UiActions). A new load keeps the
 * panels of blocks that are still there; another pipeline brings back the panels saved for it.
 */
import { useCallback, useEffect, useMemo, useRef, useState } from "react";
import type { BlockInfo, GraphInfo } from "../../engine/protocol";
import type { OpenPanel } from "./panel-host";
import type { UiActions } from "./ui-context";
import type { Notify } from "./use-notice";
import { usePanelLayouts } from "./use-panel-layouts";

export interface ShellPanels {
  panels: OpenPanel[];
  /** The loaded graph's blocks by name. */
  blocks: ReadonlyMap<string, BlockInfo>;
  /** The names of the blocks whose panel is open. */
  openSet: ReadonlySet<string>;
  ui: UiActions;
  /** The Stimulus block shown full screen (null: none). */
  stimulus: string | null;
  setStimulus(name: string | null): void;
  /** PanelHost's onUpdate: a panel floated is raised above the others. */
  onUpdate(name: string, u: Partial<OpenPanel>): void;
  /** PanelHost's onRaise: a floating panel comes to the top. */
  onRaise(name: string): void;
}

type SetPanels = (f: (ps: OpenPanel[]) => OpenPanel[]) => void;

/** A new load keeps the panels of blocks that are still there (same name and type). */
function useKeepPanels(
  graph: GraphInfo | undefined,
  setPanels: SetPanels,
  setStimulus: (f: (s: string | null) => string | null) => void,
): void {
  const lastGraph = useRef(graph);
  useEffect(() => {
    const prev = lastGraph.current;
    lastGraph.current = graph;
    if (prev === graph) return;
    setPanels((ps) =>
      ps.filter((p) => {
        const before = prev?.blocks.find((b) => b.name === p.name);
        const now = graph?.blocks.find((b) => b.name === p.name);
        return now !== undefined && before?.type === now.type;
      }),
    );
    setStimulus((s) => (s !== null && graph?.blocks.some((b) => b.name === s) ? s : null));
  }, [graph, setPanels, setStimulus]);
}

/** UiActions over the panels: toggle, open (raised, expanded) or close a block's panel. */
function useUiActions(
  setPanels: SetPanels,
  newPanel: (name: string, count: number) => OpenPanel,
  nextZ: () => number,
  setStimulus: (name: string) => void,
  notify: Notify,
  writeLiveValues: () => void,
): UiActions {
  return useMemo<UiActions>(
    () => ({
      togglePanel: (name) =>
        setPanels((ps) =>
          ps.some((p) => p.name === name)
            ? ps.filter((p) => p.name !== name)
            : [...ps, newPanel(name, ps.length)],
        ),
      openPanel: (name) =>
        setPanels((ps) =>
          ps.some((p) => p.name === name)
            ? ps.map((p) => (p.name === name ? { ...p, collapsed: false, z: nextZ() } : p))
            : [...ps, newPanel(name, ps.length)],
        ),
      closePanel: (name) => setPanels((ps) => ps.filter((p) => p.name !== name)),
      openStimulus: (name) => setStimulus(name),
      notify,
      writeLiveValues,
    }),
    [notify, writeLiveValues],
  );
}

export function useShellPanels(
  graph: GraphInfo | undefined,
  notify: Notify,
  writeLiveValues: () => void,
): ShellPanels {
  const [panels, setPanels] = useState<OpenPanel[]>([]);
  const zTop = useRef(10);
  const blocks = useMemo(() => new Map((graph?.blocks ?? []).map((b) => [b.name, b])), [graph]);
  const openSet = useMemo(() => new Set(panels.map((p) => p.name)), [panels]);
  const nextZ = useCallback(() => ++zTop.current, []);
  const newPanel = (name: string, count: number): OpenPanel => ({
    name,
    floating: false,
    collapsed: false,
    x: 60 + (count % 6) * 32,
    y: 40 + (count % 6) * 32,
    z: nextZ(),
  });
  const [stimulus, setStimulus] = useState<string | null>(null);
  const ui = useUiActions(setPanels, newPanel, nextZ, setStimulus, notify, writeLiveValues);
  useKeepPanels(graph, setPanels, setStimulus);
  // Another pipeline (or the page) loaded: the panels saved for it come back (localStorage).
  usePanelLayouts(graph, panels, setPanels, nextZ);

  const onUpdate = (name: string, u: Partial<OpenPanel>): void =>
    setPanels((ps) =>
      ps.map((p) =>
        p.name === name
          ? { ...p, ...u, ...(u.floating === true && !p.floating ? { z: nextZ() } : {}) }
          : p,
      ),
    );
  const onRaise = (name: string): void =>
    setPanels((ps) => {
      const p = ps.find((x) => x.name === name);
      if (!p || !p.floating || p.z === zTop.current) return ps;
      const z = nextZ();
      return ps.map((x) => (x.name === name ? { ...x, z } : x));
    });
  return { panels, blocks, openSet, ui, stimulus, setStimulus, onUpdate, onRaise };
}
