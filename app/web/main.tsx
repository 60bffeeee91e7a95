/**
 * The UI's entry. In the browser build it starts the engine in a Web Worker (simulated signals,
 * no install); served by `mosaic serve` (a `?token=` in the URL) it talks to the Node host over a
 * WebSocket; in the desktop app (a `mosaicHost` from the preload) over IPC. The last two share
 * one engine with other windows. `?pipeline=pipelines/x.yaml` picks the pipeline loaded first.
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
import { workerConnection } from "./worker-connection";

const desktop = desktopHost();
const socketUrl = hostSocketUrl(window.location);
const host =
  !desktop && socketUrl
    ? wsConnection(new WebSocket(socketUrl) as unknown as SocketLike)
    : undefined;
const connection = desktop
  ? ipcConnection(desktop)
  : (host ?? workerConnection(new URL("./engine.worker.js", import.meta.url)));
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

const root = document.getElementById("root");
if (!root) throw new Error("index.html has no #root element");
createRoot(root).render(
  <App
    client={client}
    initialPipeline={initial}
    sharedEngine={sharedEngine}
    engine={engine}
    {...(host ? { connection: host } : {})}
  />,
);
