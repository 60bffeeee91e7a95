/**
 * Keeps a floating panel off the node that opened it (issue 17, defect 6; the placement is
 * panel-placement.ts): when it floats, when its size changes and when the graph moves under it.
 */
import { useLayoutEffect, type RefObject } from "react";
import { placeBeside, type Rect } from "./panel-placement";

/** The node of `block` in the BlockTable, relative to `area`; undefined when not shown. */
function nodeRect(block: string, area: HTMLElement): Rect | undefined {
  const el = area.parentElement?.querySelector(`.react-flow__node[data-id="${CSS.escape(block)}"]`);
  if (!el) return undefined;
  const n = el.getBoundingClientRect();
  const a = area.getBoundingClientRect();
  return { x: n.left - a.left, y: n.top - a.top, width: n.width, height: n.height };
}

/**
 * Keeps the floating panel `ref` of `block` off its node: when it starts floating and whenever
 * its size changes; `move` commits a new position.
 */
export function useAvoidNode(
  ref: RefObject<HTMLElement | null>,
  block: string,
  floating: boolean,
  move: (p: { x: number; y: number }) => void,
): void {
  useLayoutEffect(() => {
    const el = ref.current;
    if (!floating || !el) return undefined;
    const place = (): void => {
      const area = el.offsetParent as HTMLElement | null;
      if (!area) return;
      const node = nodeRect(block, area);
      if (!node) return;
      const current = { x: el.offsetLeft, y: el.offsetTop };
      const size = { width: el.offsetWidth, height: el.offsetHeight };
      const p = placeBeside(node, current, size, {
        width: area.clientWidth,
        height: area.clientHeight,
      });
      if (p.x === current.x && p.y === current.y) return;
      el.style.left = `${p.x}px`;
      el.style.top = `${p.y}px`;
      if (p.width !== undefined) el.style.width = `${p.width}px`;
      if (p.height !== undefined) el.style.maxHeight = `${p.height}px`;
      move({ x: p.x, y: p.y });
    };
    place();
    // Again when the panel changes size, and when the graph moves under it (a fit after the
    // dock changed, a pan, a zoom, the node dragged).
    const ro = new ResizeObserver(place);
    ro.observe(el);
    const mo = new MutationObserver(place);
    const graph = el.offsetParent?.parentElement;
    const watch = graph?.querySelectorAll(
      `.react-flow__viewport, .react-flow__node[data-id="${CSS.escape(block)}"]`,
    );
    for (const w of watch ?? []) mo.observe(w, { attributes: true, attributeFilter: ["style"] });
    return () => {
      ro.disconnect();
      mo.disconnect();
    };
    // Not on every render (`move` is a new function each time): that would undo a drag.
  }, [ref, block, floating]);
}
