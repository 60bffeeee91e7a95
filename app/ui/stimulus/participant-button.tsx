/**
 * The clinician's "Participant window" button: opens the participant screen of a Stimulus block
 * in a window of its own, to be put on the participant's monitor (the desktop app opens it on a
 * second display itself). In the browser build the page lends its engine to that window over the
 * relay named by `ParticipantRelayContext` (app/web/participant-relay.ts).
 */
import { createContext, useContext } from "react";
import { participantUrl } from "./participant-link";

/** The relay channel of the browser build's page (undefined: the engine is shared already). */
export const ParticipantRelayContext = createContext<string | undefined>(undefined);

export function ParticipantButton({ block }: { block: string }) {
  const relay = useContext(ParticipantRelayContext);
  const open = (): void => {
    const url = participantUrl(window.location.href, block, relay);
    const w = window.open(url, `mosaic-participant-${block}`, "popup,width=1280,height=800");
    w?.focus();
  };
  return (
    <button
      type="button"
      className="participant-button"
      onClick={open}
      data-participant-block={block}
      title="Open the participant's screen in a window of its own (move it to the participant's monitor; double-click it for full screen)"
    >
      Participant window ↗
    </button>
  );
}
