/**
 * A block panel's view state besides its tab: the output shown (outputs with values; timers'
 * ticks carry none) and the scope, spider and heatmap settings, restored from a saved view.
 */
import { useCallback, useState } from "react";
import { restoreSettings, type PanelView } from "../app/panel-layouts";
import type { BlockInfo } from "../../engine/protocol";
import { HEATMAP_DEFAULTS, type HeatmapSettings } from "./heatmap";
import { SCOPE_DEFAULTS, type ScopeSettings } from "./scope";
import { SPIDER_DEFAULTS, type SpiderSettings } from "./spider";
import type { OutputInfo } from "./view-props";

export interface ViewSettings {
  scope: ScopeSettings;
  spider: SpiderSettings;
  heatmap: HeatmapSettings;
}

export type PatchSettings = <K extends keyof ViewSettings>(
  k: K,
) => (p: Partial<ViewSettings[K]>) => void;

export interface PanelOutput {
  /** The outputs with values. */
  valued: OutputInfo[];
  /** The one shown (the first with values unless one was chosen). */
  output: OutputInfo | undefined;
  setPort(name: string): void;
}

export function usePanelOutput(block: BlockInfo, view: PanelView | undefined): PanelOutput {
  const outputs = block.outputs as OutputInfo[];
  const valued = outputs.filter((o) => o.shape.rows * o.shape.cols > 0);
  const [portName, setPort] = useState<string | undefined>(view?.port ?? valued[0]?.name);
  const output = valued.find((o) => o.name === portName) ?? valued[0];
  return { valued, output, setPort };
}

export function useViewSettings(view: PanelView | undefined): {
  settings: ViewSettings;
  patch: PatchSettings;
} {
  const [settings, setSettings] = useState<ViewSettings>(() => ({
    scope: restoreSettings(SCOPE_DEFAULTS, view?.settings?.scope),
    spider: restoreSettings(SPIDER_DEFAULTS, view?.settings?.spider),
    heatmap: restoreSettings(HEATMAP_DEFAULTS, view?.settings?.heatmap),
  }));
  const patch = useCallback<PatchSettings>(
    (k) => (p) => setSettings((s) => ({ ...s, [k]: { ...s[k], ...p } })),
    [],
  );
  return { settings, patch };
}
