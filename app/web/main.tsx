/**
 * The UI's entry. In the browser build it starts the engine in a Web Worker (simulated signals,
 * no install); served by `mosaic serve` (a `?token=` in the URL) it talks to the Node host over a
 * WebSocket; in the desktop app (a `mosaicHost` from the preload) over IPC. The last two share
 * one engine with other windows. `?pipeline=pipelines/x.yaml` picks the pipeline loaded first.
 * `?view=participant&block=NAME` is the participant window (app/ui/stimulus/participant-app.tsx):
 * over the same transports, or in the browser build over the opener's relay (`&relay=ID`, see
 * participant-relay.ts), never with an engine of its own.
 */
import { createRoot } from "react-dom/client";
import "@xyflow/react/dist/style.css";
import "../ui/styles.css";
import { App } from "../ui/app/app";
import { DEFAULT_PIPELINE } from "../ui/app/use-pipeline";
import type { EngineWhere } from "../ui/client/connection-status";
import { EngineClient } from "../ui/client/engine-client";
import { desktopHost, ipcConnection } from "../ui/client/ipc-connection";
import { hostSocketUrl, wsConnection, type SocketLike } from "../ui/client/ws-connection";
import { ParticipantApp } from "../ui/stimulus/participant-app";
import { ParticipantRelayContext } from "../ui/stimulus/participant-button";
import { participantParams } from "../ui/stimulus/participant-link";
import { openChannel, relayConnection, startParticipantRelay } from "./participant-relay";
import { workerConnection } from "./worker-connection";

const desktop = desktopHost();
const socketUrl = hostSocketUrl(window.location);
const participant = participantParams(window.location.search);
const host =
  !desktop && socketUrl
    ? wsConnection(new WebSocket(socketUrl) as unknown as SocketLike)
    : undefined;
// A participant window of the browser build follows the engine of the page that opened it
// (and never starts one of its own).
const relayed =
  !desktop && !host && participant
    ? relayConnection(openChannel(participant.relay ?? ""))
    : undefined;
const connection = desktop
  ? ipcConnection(desktop)
  : (host ?? relayed ?? workerConnection(new URL("./engine.worker.js", import.meta.url)));
const sharedEngine = desktop !== undefined || socketUrl !== null;
// The toolbar names the engine: no token in the URL means this page runs its own.
const engine: EngineWhere = desktop
  ? { kind: "desktop" }
  : host
    ? { kind: "host", address: window.location.host }
    : { kind: "page" };
const client = new EngineClient(connection);
// For the curious (devtools) and for end-to-end tests: the client speaks the UI protocol.
(window as unknown as { mosaic: { client: EngineClient } }).mosaic = { client };

const params = new URLSearchParams(window.location.search);
const initial = params.get("pipeline") || DEFAULT_PIPELINE;

/** The browser build's page lends its engine to participant windows (one channel per tab). */
function lendEngine(): string | undefined {
  if (engine.kind !== "page" || typeof BroadcastChannel === "undefined") return undefined;
  const id = sessionStorage.getItem(RELAY_KEY) ?? `r${Math.random().toString(36).slice(2)}`;
  sessionStorage.setItem(RELAY_KEY, id);
  const stop = startParticipantRelay(client, openChannel(id));
  // Its participant windows say so when this page closes (and pick up again if it reloads).
  window.addEventListener("pagehide", stop);
  return id;
}
const RELAY_KEY = "mosaic-participant-relay";

const root = document.getElementById("root");
if (!root) throw new Error("index.html has no #root element");
if (participant) {
  if (relayed) window.addEventListener("pagehide", () => relayed.close());
  const problem =
    relayed && participant.relay === undefined
      ? "Open this window with the Participant window button of the clinician's MOSAIC page."
      : undefined;
  createRoot(root).render(
    <ParticipantApp
      client={client}
      block={participant.block}
      {...(relayed ? { link: relayed } : {})}
      {...(problem !== undefined ? { problem } : {})}
    />,
  );
} else {
  createRoot(root).render(
    <ParticipantRelayContext.Provider value={lendEngine()}>
      <App
        client={client}
        initialPipeline={initial}
        sharedEngine={sharedEngine}
        engine={engine}
        {...(host ? { connection: host } : {})}
      />
    </ParticipantRelayContext.Provider>,
  );
}
