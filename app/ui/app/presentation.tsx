/**
 * Presentation mode (issue 17, defect 6): larger type everywhere for a projector or a room — the
 * toolbar, the panels and the footer drawn 1.25× (presentation.css), the graph's text at least
 * 15 px on screen (app/ui/graph/readable-zoom.ts). A toolbar toggle; remembered in this browser
 * (localStorage), and shown on the page as `data-presentation` on the root element.
 */
import { useCallback, useEffect, useState } from "react";
import "./presentation.css";

const KEY = "mosaic.presentation";
/** Dispatched on `window` when the mode changes. */
export const PRESENTATION_EVENT = "mosaic-presentation";

function stored(): boolean {
  try {
    return window.localStorage.getItem(KEY) === "on";
  } catch {
    return false;
  }
}

function apply(on: boolean): void {
  document.documentElement.dataset.presentation = String(on);
  window.dispatchEvent(new Event(PRESENTATION_EVENT));
}

/** Whether presentation mode is on now. */
export function isPresentation(): boolean {
  return document.documentElement.dataset.presentation === "true";
}

/** The mode and its switch (the first call applies the remembered mode). */
export function usePresentation(): [boolean, (on: boolean) => void] {
  const [on, setOn] = useState(stored);
  useEffect(() => apply(on), [on]);
  const set = useCallback((v: boolean) => {
    try {
      window.localStorage.setItem(KEY, v ? "on" : "off");
    } catch {
      /* private mode: the mode lasts as long as the page */
    }
    setOn(v);
  }, []);
  return [on, set];
}

/** The toolbar's toggle. */
export function PresentationToggle() {
  const [on, set] = usePresentation();
  return (
    <button
      type="button"
      className="presentation-toggle"
      aria-pressed={on}
      onClick={() => set(!on)}
      title="Presentation mode: larger type everywhere, for a projector or a room (remembered)"
    >
      Presentation
    </button>
  );
}
