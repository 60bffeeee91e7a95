/**
 * What any part of the UI (a control panel included) may ask the app shell to do: open or close
 * a block's control panel, show a Stimulus block full screen, report a message in the log.
 */
import { createContext, useContext } from "react";

export interface UiActions {
  togglePanel(block: string): void;
  openPanel(block: string): void;
  closePanel(block: string): void;
  /** Shows a Stimulus block's participant view full screen. */
  openStimulus(block: string): void;
  /** A line in the event log (and a short notice), e.g. the reply of an action. */
  notify(message: string, level?: "info" | "error", block?: string): void;
  /** Writes the live values that are not the file's back into it (issue 17, defect 1). */
  writeLiveValues?(): void;
}

const noop = (): void => {};

export const UiContext = createContext<UiActions>({
  togglePanel: noop,
  openPanel: noop,
  closePanel: noop,
  openStimulus: noop,
  notify: noop,
});

export function useUi(): UiActions {
  return useContext(UiContext);
}
