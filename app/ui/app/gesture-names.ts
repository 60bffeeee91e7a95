/**
 * The gestures of an EmgSimulator block: its `Gestures` param's names, or the default set (the
 * EmgSimulator's own list, app/blocks/sources/emg-simulator.ts, which the UI may not import).
 */
import type { BlockInfo } from "../../engine/protocol";

export const DEFAULT_GESTURES = [
  "rest",
  "fist",
  "open",
  "pinch",
  "flexion",
  "extension",
  "pronation",
  "supination",
] as const;

export function gestureNames(block: BlockInfo): string[] {
  const g = block.params.Gestures;
  if (g !== null && typeof g === "object" && !Array.isArray(g)) {
    const names = Object.keys(g);
    if (names.length > 0) return names;
  }
  return [...DEFAULT_GESTURES];
}

/** The gesture a key selects: 1–9 the n-th gesture, 0 and Space rest (or the first gesture). */
export function gestureForKey(key: string, names: readonly string[]): string | undefined {
  if (key === "0" || key === " ") return names.includes("rest") ? "rest" : names[0];
  if (/^[1-9]$/.test(key)) return names[Number(key) - 1];
  return undefined;
}
