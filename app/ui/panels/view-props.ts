import type { ReactNode } from "react";
import type { ElectrodeGrid } from "../../engine/block";
import type { BlockInfo } from "../../engine/protocol";

/** One output of a block, as BlockInfo lists it (labels, unit, grid: its PortMeta, when known). */
export interface OutputInfo {
  name: string;
  shape: { rows: number; cols: number };
  labels?: readonly string[];
  unit?: string;
  grid?: ElectrodeGrid;
}

/** What every data view of a control panel gets. */
export interface ViewProps<S> {
  block: BlockInfo;
  output: OutputInfo;
  /** The panel is visible and this view is the open tab: only then is data watched and drawn. */
  active: boolean;
  settings: S;
  onSettings: (patch: Partial<S>) => void;
  /** Controls the panel adds at the start of the view's toolbar (the output picker). */
  tools?: ReactNode;
}
