/**
 * The edge between the graph and the docked panels: dragged (or moved with the arrow keys while
 * focused) it sets the dock's width, so docked scopes can take most of the screen. The width is
 * remembered in the browser (localStorage) for every pipeline; a double click forgets it.
 */
import { useCallback, useState, type ReactNode } from "react";

const KEY = "mosaic.dockWidth";
const MIN = 300;

/** The dock's width chosen by the user (px), or undefined for the stylesheet's. */
export function useDockWidth(): [number | undefined, (w: number | undefined) => void] {
  const [width, setWidth] = useState<number | undefined>(() => {
    const v = Number(globalThis.localStorage?.getItem(KEY));
    return Number.isFinite(v) && v >= MIN ? v : undefined;
  });
  const set = useCallback((w: number | undefined) => {
    setWidth(w);
    try {
      if (w === undefined) localStorage.removeItem(KEY);
      else localStorage.setItem(KEY, String(Math.round(w)));
    } catch {
      // Storage refused (private mode): the width holds for this page only.
    }
  }, []);
  return [width, set];
}

/** A width between MIN and all but 200 px of the workspace. */
function clampWidth(w: number, workspace: number): number {
  return Math.round(Math.max(MIN, Math.min(Math.max(MIN, workspace - 200), w)));
}

export function DockResizer({
  width,
  onWidth,
}: {
  width: number | undefined;
  onWidth(w: number | undefined): void;
}): ReactNode {
  const dockOf = (el: HTMLElement): HTMLElement | null =>
    el.nextElementSibling instanceof HTMLElement ? el.nextElementSibling : null;
  const onPointerDown = (e: React.PointerEvent<HTMLDivElement>): void => {
    if (e.button !== 0) return;
    const el = e.currentTarget;
    const dock = dockOf(el);
    const space = el.parentElement?.clientWidth ?? window.innerWidth;
    if (!dock) return;
    el.setPointerCapture(e.pointerId);
    const start = { x: e.clientX, w: dock.offsetWidth };
    const move = (m: PointerEvent): void => {
      // Moved directly while dragging (no React render per event); committed on release.
      dock.style.width = `${clampWidth(start.w + start.x - m.clientX, space)}px`;
    };
    const up = (): void => {
      el.removeEventListener("pointermove", move);
      el.removeEventListener("pointerup", up);
      el.removeEventListener("pointercancel", up);
      onWidth(dock.offsetWidth);
    };
    el.addEventListener("pointermove", move);
    el.addEventListener("pointerup", up);
    el.addEventListener("pointercancel", up);
  };
  const onKeyDown = (e: React.KeyboardEvent<HTMLDivElement>): void => {
    const step = { ArrowLeft: 40, ArrowRight: -40 }[e.key];
    const dock = dockOf(e.currentTarget);
    if (step === undefined || !dock) return;
    e.preventDefault();
    const space = e.currentTarget.parentElement?.clientWidth ?? window.innerWidth;
    onWidth(clampWidth(dock.offsetWidth + step * (e.shiftKey ? 4 : 1), space));
  };
  return (
    <div
      className="dock-resizer"
      role="separator"
      aria-orientation="vertical"
      aria-label="Width of the panel area: drag, or arrow keys"
      aria-valuenow={width}
      tabIndex={0}
      title="Drag to widen the panels (double-click: default width)"
      style={{ flex: "none", width: 6, cursor: "col-resize", touchAction: "none" }}
      onPointerDown={onPointerDown}
      onKeyDown={onKeyDown}
      onDoubleClick={() => onWidth(undefined)}
    />
  );
}
