/**
 * Text in the BlockTable stays readable at any zoom (issue 17, defect 6). The graph's zoom is
 * written on its box as `--graph-zoom`; readable.css sizes every text of the graph as
 * max(its size, the minimum on screen ÷ zoom), so nothing is drawn under the minimum (11.25 px,
 * 15 px in presentation mode). Where that no longer fits a node the graph is summarised instead
 * (`data-text` on the box): "full" draws everything; "compact" keeps each node's name, status and
 * rate and hides edge labels (the source node shows the same rate; a label with dropped events
 * stays); "minimal" keeps the name and the status icon.
 */
import { useStore, type ReactFlowState } from "@xyflow/react";
import { useEffect, useLayoutEffect, useState, type RefObject } from "react";
import { isPresentation, PRESENTATION_EVENT } from "../app/presentation";
import "./readable.css";

/** The smallest text on screen, CSS px (the acceptance test asks for 11). */
export const MIN_TEXT_PX = 11.25;
/** In presentation mode (a projector, a room). */
export const PRESENTATION_TEXT_PX = 15;

export type TextMode = "full" | "compact" | "minimal";

/** The smallest text a full node draws (its type and note lines), px at zoom 1. */
const SMALLEST_FULL = 12;
/** How big, at zoom 1, a compact node's three lines may be and still fit its box. */
const LARGEST_COMPACT = 24;

/** What the graph shows at `zoom` when no text may be under `minPx` on screen. */
export function textMode(zoom: number, minPx: number): TextMode {
  if (zoom * SMALLEST_FULL >= minPx) return "full";
  if (zoom * LARGEST_COMPACT >= minPx) return "compact";
  return "minimal";
}

const zoomOf = (s: ReactFlowState): number => s.transform[2];

/** Follows the presentation switch (app/ui/app/presentation.ts). */
function usePresentationOn(): boolean {
  const [on, setOn] = useState(isPresentation);
  useEffect(() => {
    const update = (): void => setOn(isPresentation());
    window.addEventListener(PRESENTATION_EVENT, update);
    return () => window.removeEventListener(PRESENTATION_EVENT, update);
  }, []);
  return on;
}

/**
 * Keeps `--graph-zoom`, `--graph-min-text` and `data-text` of the graph's box up to date. Render
 * it inside the React Flow provider; it draws nothing and re-renders only itself on zoom.
 */
export function ReadableZoom({ target }: { target: RefObject<HTMLElement | null> }): null {
  const zoom = useStore(zoomOf);
  const presentation = usePresentationOn();
  useLayoutEffect(() => {
    const el = target.current;
    if (!el) return;
    const min = presentation ? PRESENTATION_TEXT_PX : MIN_TEXT_PX;
    el.style.setProperty("--graph-zoom", String(zoom));
    el.style.setProperty("--graph-min-text", `${min}px`);
    el.dataset.text = textMode(zoom, min);
  }, [target, zoom, presentation]);
  return null;
}
