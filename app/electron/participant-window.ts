/**
 * The participant window of the desktop app (issue 17): the page's "Participant window" button
 * asks `window.open` for `…/index.html?view=participant&block=NAME`; the main process opens that
 * page in a window of its own (same preload, same engine) and puts it on a second display, full
 * screen, when there is one. Plain functions of URLs and display geometry, tested without
 * Electron.
 */
import { isAllowedNavigation } from "./security";

/** Whether `window.open(url)` asks for a participant window of the app. */
export function isParticipantUrl(url: string): boolean {
  if (!isAllowedNavigation(url)) return false;
  return new URL(url).searchParams.get("view") === "participant";
}

export interface Rect {
  x: number;
  y: number;
  width: number;
  height: number;
}

/** What the main process reads of Electron's `Display`. */
export interface DisplayLike {
  id: number;
  bounds: Rect;
  workArea: Rect;
}

export interface ParticipantPlacement {
  bounds: Rect;
  /** Full screen on a display of its own; a window beside the clinician's on a single display. */
  fullscreen: boolean;
}

const WINDOW = { width: 1280, height: 800 };

/**
 * Where the participant window goes: full screen on a display other than the clinician's
 * window's (the first one found), else a 1280×800 window centred in the clinician's display's
 * work area (smaller when the display is).
 */
export function participantPlacement(
  displays: readonly DisplayLike[],
  clinician: DisplayLike,
): ParticipantPlacement {
  const other = displays.find((d) => d.id !== clinician.id);
  if (other) return { bounds: { ...other.bounds }, fullscreen: true };
  const area = clinician.workArea;
  const width = Math.min(WINDOW.width, area.width);
  const height = Math.min(WINDOW.height, area.height);
  return {
    bounds: {
      x: Math.round(area.x + (area.width - width) / 2),
      y: Math.round(area.y + (area.height - height) / 2),
      width,
      height,
    },
    fullscreen: false,
  };
}
