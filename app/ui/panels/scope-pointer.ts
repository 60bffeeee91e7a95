/**
 * The scope under the pointer (DOM, no React): the wheel zooms time around the cursor (with
 * Shift or Alt: the amplitude), a drag pans time (with Shift: the amplitude) and holds the view
 * (the scope pauses), a double click resets the zoom; the readout shows the time and each
 * channel's value under the cursor.
 */
import type uPlot from "uplot";
import { formatValue } from "./channels";
import type { ScopeLive } from "./scope-draw";
import { nearestIndex, panRange, zoomRange } from "./scope-view";

export interface PointerCallbacks {
  /** The view was zoomed or panned (zoomed: it differs from the window). */
  onView(zoomed: boolean): void;
  /** A drag began while the scope followed the data: hold the picture. */
  onHold(): void;
  /** Double click: back to the whole window and the automatic amplitude. */
  onReset(): void;
}

/** Shortest time span a zoom reaches, s. */
const MIN_SPAN_S = 0.01;

export function isZoomed(l: ScopeLive, windowS: number): boolean {
  return Math.abs(l.span - windowS) > 1e-9 || l.yView !== null || l.laneGain !== 1;
}

function zoomAmplitude(l: ScopeLive, u: uPlot, e: WheelEvent, factor: number): void {
  if (l.stacked) {
    l.laneGain = Math.min(1e6, Math.max(1e-6, l.laneGain * factor));
    return;
  }
  const anchor = u.posToVal(e.offsetY, "y");
  l.yView = zoomRange(
    l.yView ?? l.y,
    factor,
    Number.isFinite(anchor) ? anchor : (l.y[0] + l.y[1]) / 2,
  );
}

function zoomTime(l: ScopeLive, u: uPlot, e: WheelEvent, factor: number, maxSpan: number): void {
  const anchor = u.posToVal(e.offsetX, "x");
  const r = zoomRange(l.x, factor, Number.isFinite(anchor) ? anchor : l.x[1]);
  l.span = Math.max(MIN_SPAN_S, Math.min(maxSpan, r[1] - r[0]));
  // Following the data, the right edge stays "now"; a held view zooms around the cursor.
  if (Number.isFinite(l.right)) l.right = r[0] + l.span;
}

/** The readout's lines at plot x `px` (CSS pixels from the plot area's left): time, then values. */
export function readoutLines(
  l: ScopeLive,
  u: uPlot,
  px: number,
): { t: string; values: string[] } | null {
  const b = l.buffer;
  if (!b || b.count === 0) return null;
  const x = u.posToVal(px, "x");
  const data = b.view(l.x[0], l.x[1]);
  const i = nearestIndex(data[0]!, x);
  if (i < 0) return null;
  const unit = l.unit ? ` ${l.unit}` : "";
  const values: string[] = [];
  for (let c = 1; c < data.length; c++)
    values.push(`${l.names[c - 1] ?? c - 1}: ${formatValue(data[c]![i]!)}${unit}`);
  return { t: `t = ${data[0]![i]!.toFixed(3)} s`, values };
}

/** Writes the readout into `box` (one line each) and puts the cursor line at `px`. */
export function showReadout(
  box: HTMLElement,
  cursor: HTMLElement,
  lines: { t: string; values: string[] } | null,
  px: number,
  left: number,
): void {
  if (!lines) {
    box.hidden = true;
    cursor.hidden = true;
    return;
  }
  const rows = [lines.t, ...lines.values];
  while (box.childElementCount > rows.length) box.lastElementChild!.remove();
  while (box.childElementCount < rows.length) box.append(document.createElement("div"));
  rows.forEach((r, k) => {
    const el = box.children[k] as HTMLElement;
    if (el.textContent !== r) el.textContent = r;
  });
  box.hidden = false;
  cursor.hidden = false;
  cursor.style.left = `${left + px}px`;
}

interface Drag {
  x: number;
  y: number;
  right: number;
  yView: [number, number];
  shift: boolean;
}

/** Wires the wheel, drag and double click on the plot area; returns the cleanup. */
export function attachPointer(
  u: uPlot,
  l: ScopeLive,
  maxSpan: () => number,
  pointerAt: (px: number | null) => void,
  cb: PointerCallbacks,
): () => void {
  const over = u.over;
  let drag: Drag | null = null;
  const onWheel = (e: WheelEvent): void => {
    e.preventDefault();
    const factor = e.deltaY > 0 ? 1.25 : 0.8;
    if (e.shiftKey || e.altKey) zoomAmplitude(l, u, e, factor);
    else zoomTime(l, u, e, factor, maxSpan());
    l.dirty = true;
    cb.onView(true);
  };
  const onDown = (e: PointerEvent): void => {
    if (e.button !== 0) return;
    over.setPointerCapture(e.pointerId);
    drag = { x: e.clientX, y: e.clientY, right: l.x[1], yView: l.yView ?? l.y, shift: e.shiftKey };
  };
  const onMove = (e: PointerEvent): void => {
    pointerAt(e.offsetX);
    if (!drag) return;
    const dx = e.clientX - drag.x;
    const dy = e.clientY - drag.y;
    if (!Number.isFinite(l.right) && Math.abs(dx) + Math.abs(dy) < 3) return;
    if (!Number.isFinite(l.right)) cb.onHold();
    if (drag.shift && !l.stacked) {
      const h = over.clientHeight || 1;
      l.yView = panRange(drag.yView, (dy * (drag.yView[1] - drag.yView[0])) / h);
    } else {
      const w = over.clientWidth || 1;
      l.right = drag.right - (dx * l.span) / w;
    }
    l.dirty = true;
    cb.onView(true);
  };
  const onUp = (): void => {
    drag = null;
  };
  const onLeave = (): void => pointerAt(null);
  const onDbl = (): void => cb.onReset();
  over.addEventListener("wheel", onWheel, { passive: false });
  over.addEventListener("pointerdown", onDown);
  over.addEventListener("pointermove", onMove);
  over.addEventListener("pointerup", onUp);
  over.addEventListener("pointercancel", onUp);
  over.addEventListener("pointerleave", onLeave);
  over.addEventListener("dblclick", onDbl);
  return () => {
    over.removeEventListener("wheel", onWheel);
    over.removeEventListener("pointerdown", onDown);
    over.removeEventListener("pointermove", onMove);
    over.removeEventListener("pointerup", onUp);
    over.removeEventListener("pointercancel", onUp);
    over.removeEventListener("pointerleave", onLeave);
    over.removeEventListener("dblclick", onDbl);
  };
}
