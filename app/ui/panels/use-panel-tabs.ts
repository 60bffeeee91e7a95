/**
 * A block panel's tabs: one per data view the block declares, then Params and Status. The tab
 * opened first is the saved view's (when the block still has it); arrows, Home and End move
 * between tabs (roving focus).
 */
import { useId, useMemo, useState, type KeyboardEvent } from "react";

export type DataView = "scope" | "spider" | "heatmap" | "label" | "training" | "player";
export type Tab = DataView | "params" | "status";

export const TAB_TITLE: Record<Tab, string> = {
  scope: "Scope",
  spider: "Spider",
  heatmap: "Heatmap",
  label: "Labels",
  training: "Training",
  player: "Player",
  params: "Params",
  status: "Status",
};
export const DATA_VIEWS: readonly string[] = [
  "scope",
  "spider",
  "heatmap",
  "label",
  "training",
  "player",
];

export interface PanelTabs {
  tabs: Tab[];
  /** The open tab. */
  tab: Tab;
  setTab(t: Tab): void;
  /** The prefix of the tabs' and the tab panel's ids. */
  base: string;
  onTabKey(e: KeyboardEvent<HTMLDivElement>): void;
}

/** The tab index the key moves to, or -2 for a key that does not move. */
function keyTarget(key: string, i: number, count: number): number {
  if (key === "ArrowRight") return i + 1;
  if (key === "ArrowLeft") return i - 1;
  if (key === "Home") return 0;
  if (key === "End") return count - 1;
  return -2;
}

export function usePanelTabs(views: readonly string[], saved: string | undefined): PanelTabs {
  const tabs = useMemo<Tab[]>(
    () => [...(views.filter((v) => DATA_VIEWS.includes(v)) as DataView[]), "params", "status"],
    [views],
  );
  const [chosen, setTab] = useState<Tab>(() => (saved as Tab | undefined) ?? tabs[0]!);
  const tab = tabs.includes(chosen) ? chosen : tabs[0]!;
  const base = useId();
  const onTabKey = (e: KeyboardEvent<HTMLDivElement>): void => {
    const next = keyTarget(e.key, tabs.indexOf(tab), tabs.length);
    if (next === -2) return;
    e.preventDefault();
    const t = tabs[(next + tabs.length) % tabs.length]!;
    setTab(t);
    document.getElementById(`${base}-tab-${t}`)?.focus();
  };
  return { tabs, tab, setTab, base, onTabKey };
}
