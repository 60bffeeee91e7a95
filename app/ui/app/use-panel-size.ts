/**
 * A floating panel is resized by its corner (CSS `resize`, panel-size.css); the size the user
 * gives it is kept in its OpenPanel (and so in the saved panel layout). The browser writes a
 * resized element's size into its inline style: that is what is read here, so a size that only
 * follows the content is never mistaken for one the user chose.
 */
import { useEffect, useRef, type RefObject } from "react";
import "./panel-size.css";

export function usePanelSize(
  ref: RefObject<HTMLElement | null>,
  floating: boolean,
  size: { width?: number | undefined; height?: number | undefined },
  onSize: (s: { width: number; height: number }) => void,
): void {
  const latest = useRef({ size, onSize });
  latest.current = { size, onSize };
  useEffect(() => {
    const el = ref.current;
    if (!el || !floating || typeof ResizeObserver !== "function") return undefined;
    const ro = new ResizeObserver(() => {
      const width = Math.round(parseFloat(el.style.width));
      const height = Math.round(parseFloat(el.style.height));
      if (!Number.isFinite(width) || !Number.isFinite(height)) return;
      const { size: now, onSize: tell } = latest.current;
      if (width !== now.width || height !== now.height) tell({ width, height });
    });
    ro.observe(el);
    return () => ro.disconnect();
  }, [ref, floating]);
}
