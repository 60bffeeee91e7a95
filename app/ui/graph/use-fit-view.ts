/**
 * Fitting the BlockTable's view: the whole pipeline at a zoom that can be read, done once the
 * nodes are measured and again whenever the area changes size, until the user pans or zooms.
 */
import { useNodesInitialized, useReactFlow } from "@xyflow/react";
import { useCallback, useEffect, useRef, useState, type RefObject } from "react";

/** Fit the pipeline, but never so small that it cannot be read (pan for the rest). */
const FIT = { padding: 0.08, minZoom: 0.5, maxZoom: 1.25 };

export interface FitView {
  /** The graph's area (the element whose size the view fits). */
  box: RefObject<HTMLDivElement | null>;
  /** The first fit was done (the nodes were measured). */
  fitted: boolean;
  /**
   * "Show the whole pipeline" (animated over `duration`), and again after every new size until
   * the user pans or zooms by hand.
   */
  showAll(): void;
  /** The same on the next frame (once new node positions are drawn). */
  showAllSoon(): void;
  /** React Flow's onMoveStart: a user's pan or zoom has an event; fitView does not. */
  onMoveStart(e: MouseEvent | TouchEvent | null): void;
}

/**
 * Shows the whole pipeline (zoom between FIT.minZoom and FIT.maxZoom). When even the smallest
 * zoom is too small, it starts at the left (where the signals come from) instead of the
 * middle, so that the first blocks are never cut.
 */
function useFit(box: RefObject<HTMLDivElement | null>): (ms?: number) => void {
  const flow = useReactFlow();
  return useCallback(
    (ms = 0) => {
      const el = box.current;
      const ns = flow.getNodes();
      if (!el || ns.length === 0) return;
      const b = flow.getNodesBounds(ns);
      const w = el.clientWidth;
      const h = el.clientHeight;
      const inner = 1 - 2 * FIT.padding;
      const z = Math.min((w * inner) / b.width, (h * inner) / b.height);
      const zoom = Math.max(FIT.minZoom, Math.min(FIT.maxZoom, z));
      const fitsX = b.width * zoom <= w * inner;
      const fitsY = b.height * zoom <= h * inner;
      const x = fitsX ? (w - b.width * zoom) / 2 - b.x * zoom : w * FIT.padding - b.x * zoom;
      const y = fitsY ? (h - b.height * zoom) / 2 - b.y * zoom : h * FIT.padding - b.y * zoom;
      void flow.setViewport({ x, y, zoom }, { duration: ms });
    },
    [flow, box],
  );
}

/**
 * Fits once the nodes are measured, and again when the area changes size (a panel docked or
 * closed) until the user pans or zooms by hand.
 */
export function useFitView(duration: number): FitView {
  const box = useRef<HTMLDivElement>(null);
  const fit = useFit(box);
  const userMoved = useRef(false);
  const initialized = useNodesInitialized();
  const [fitted, setFitted] = useState(false);
  useEffect(() => {
    if (initialized && !fitted) {
      fit();
      setFitted(true);
    }
  }, [initialized, fitted, fit]);
  useEffect(() => {
    const el = box.current;
    if (!el || typeof ResizeObserver !== "function") return undefined;
    let last = el.clientWidth * 10_000 + el.clientHeight;
    const ro = new ResizeObserver(() => {
      const size = el.clientWidth * 10_000 + el.clientHeight;
      if (size === last) return;
      last = size;
      if (!userMoved.current) fit();
    });
    ro.observe(el);
    return () => ro.disconnect();
  }, [fit]);
  const showAll = (): void => {
    userMoved.current = false;
    fit(duration);
  };
  const showAllSoon = (): void => {
    userMoved.current = false;
    requestAnimationFrame(() => fit(duration));
  };
  const onMoveStart = (e: MouseEvent | TouchEvent | null): void => {
    if (e) userMoved.current = true;
  };
  return { box, fitted, showAll, showAllSoon, onMoveStart };
}
