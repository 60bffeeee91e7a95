/** Canvas helpers of the panels: device-pixel sizing, resize observation, theme colours. */
import { useEffect, type RefObject } from "react";

export interface CanvasSize {
  /** CSS pixels. */
  width: number;
  height: number;
  dpr: number;
}

/** Sizes the canvas' backing store for the device pixel ratio; returns a context in CSS pixels. */
export function fitCanvas(
  canvas: HTMLCanvasElement,
  width: number,
  height: number,
): CanvasRenderingContext2D | null {
  const dpr = Math.min(3, window.devicePixelRatio || 1);
  const w = Math.max(1, Math.round(width * dpr));
  const h = Math.max(1, Math.round(height * dpr));
  if (canvas.width !== w) canvas.width = w;
  if (canvas.height !== h) canvas.height = h;
  canvas.style.width = `${width}px`;
  canvas.style.height = `${height}px`;
  const ctx = canvas.getContext("2d");
  ctx?.setTransform(dpr, 0, 0, dpr, 0, 0);
  return ctx;
}

/** Calls `onResize(width)` with the element's CSS width now and whenever it changes. */
export function useWidth(
  ref: RefObject<HTMLElement | null>,
  onResize: (width: number) => void,
): void {
  useEffect(() => {
    const el = ref.current;
    if (!el) return undefined;
    let last = -1;
    const check = (): void => {
      const w = Math.floor(el.clientWidth);
      if (w !== last) {
        last = w;
        onResize(w);
      }
    };
    check();
    const ro = new ResizeObserver(check);
    ro.observe(el);
    return () => ro.disconnect();
  }, [ref, onResize]);
}

export interface Theme {
  fg: string;
  muted: string;
  grid: string;
  bg: string;
  accent: string;
}

/** The panel colours from CSS custom properties (panels.css), with fallbacks. */
export function readTheme(el: Element): Theme {
  const css = getComputedStyle(el);
  const v = (name: string, fallback: string): string =>
    css.getPropertyValue(name).trim() || fallback;
  return {
    fg: v("--mp-fg", "#1d2430"),
    muted: v("--mp-muted", "#5b6473"),
    grid: v("--mp-grid", "rgba(0,0,0,0.1)"),
    bg: v("--mp-bg", "#ffffff"),
    accent: v("--mp-accent", "#1f6feb"),
  };
}
