/**
 * Moving a floating panel (PanelFrame) by its title bar: dragged with the pointer (a button in the
 * bar does not start a drag) or moved with the arrow keys while the bar has the focus.
 */
import { useRef, type RefObject } from "react";
import type { OpenPanel } from "./panel-host";

/** The title bar's handlers (spread onto it). */
export interface DragHandlers {
  onPointerDown(e: React.PointerEvent<HTMLElement>): void;
  onPointerMove(e: React.PointerEvent<HTMLElement>): void;
  onPointerUp(): void;
  onPointerCancel(): void;
  onKeyDown(e: React.KeyboardEvent<HTMLElement>): void;
}

export function usePanelDrag(
  ref: RefObject<HTMLElement | null>,
  panel: Pick<OpenPanel, "floating" | "x" | "y">,
  onUpdate: (p: Partial<OpenPanel>) => void,
): DragHandlers {
  const drag = useRef<{ dx: number; dy: number } | null>(null);
  const onPointerDown = (e: React.PointerEvent<HTMLElement>): void => {
    if (!panel.floating || e.button !== 0) return;
    if ((e.target as HTMLElement).closest("button")) return;
    const el = ref.current!;
    drag.current = { dx: e.clientX - el.offsetLeft, dy: e.clientY - el.offsetTop };
    e.currentTarget.setPointerCapture(e.pointerId);
  };
  const onPointerMove = (e: React.PointerEvent<HTMLElement>): void => {
    const d = drag.current;
    const el = ref.current;
    if (!d || !el) return;
    const parent = el.offsetParent as HTMLElement | null;
    const maxX = (parent?.clientWidth ?? window.innerWidth) - 80;
    const maxY = (parent?.clientHeight ?? window.innerHeight) - 32;
    // Moved directly (no React render per pointer event); committed on release.
    el.style.left = `${Math.max(-200, Math.min(maxX, e.clientX - d.dx))}px`;
    el.style.top = `${Math.max(0, Math.min(maxY, e.clientY - d.dy))}px`;
  };
  const onPointerUp = (): void => {
    const el = ref.current;
    if (drag.current && el) onUpdate({ x: el.offsetLeft, y: el.offsetTop });
    drag.current = null;
  };
  const onKeyDown = (e: React.KeyboardEvent<HTMLElement>): void => {
    // Floating windows move with the arrow keys while their title bar has the focus.
    if (!panel.floating || e.target !== e.currentTarget) return;
    const step = e.shiftKey ? 40 : 10;
    const d = {
      ArrowLeft: [-step, 0],
      ArrowRight: [step, 0],
      ArrowUp: [0, -step],
      ArrowDown: [0, step],
    }[e.key];
    if (!d) return;
    e.preventDefault();
    onUpdate({ x: panel.x + d[0]!, y: Math.max(0, panel.y + d[1]!) });
  };
  return { onPointerDown, onPointerMove, onPointerUp, onPointerCancel: onPointerUp, onKeyDown };
}
