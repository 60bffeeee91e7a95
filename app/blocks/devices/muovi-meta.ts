/**
 * What the Muovi blocks say of their output (PortMeta): a label per channel, "probe 2 ch 17" (the
 * probe's number as printed on it, 1-based), and the electrode array on a probe's 32 channels
 * (`Grid`) for the heatmap.
 */
import { BlockConfigError, errorMessage, type ElectrodeGrid, type PortMeta } from "../../engine";
import { electrodeGrid, type GridParam } from "./electrode-arrays";
import { MUOVI_CHANNELS } from "./muovi-protocol";

/** `probes`: 0-based probe indices in output order; `unit`: of every channel, if one holds. */
export function muoviMeta(
  probes: readonly number[],
  grid: GridParam | undefined,
  unit?: string,
): PortMeta {
  const labels: string[] = [];
  for (const p of probes) {
    for (let c = 1; c <= MUOVI_CHANNELS; c++) labels.push(`probe ${p + 1} ch ${c}`);
  }
  let g: ElectrodeGrid | undefined;
  try {
    g = electrodeGrid(grid, labels.length);
  } catch (e) {
    throw new BlockConfigError(errorMessage(e), "Grid");
  }
  return { labels, ...(unit ? { unit } : {}), ...(g ? { grid: g } : {}) };
}
