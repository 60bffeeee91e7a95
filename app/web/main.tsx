/**
 * The browser build's entry: starts the engine in a Web Worker (simulated signals, no install)
 * and mounts the UI on it. `?pipeline=pipelines/x.yaml` picks the pipeline loaded first.
 */
import { createRoot } from "react-dom/client";
import "@xyflow/react/dist/style.css";
import "../ui/styles.css";
import { App } from "../ui/app/app";
import { DEFAULT_PIPELINE } from "../ui/app/use-pipeline";
import { EngineClient } from "../ui/client/engine-client";
import { workerConnection } from "./worker-connection";

const client = new EngineClient(workerConnection(new URL("./engine.worker.js", import.meta.url)));
// For the curious (devtools) and for end-to-end tests: the client speaks the UI protocol.
(window as unknown as { mosaic: { client: EngineClient } }).mosaic = { client };

const params = new URLSearchParams(window.location.search);
const initial = params.get("pipeline") || DEFAULT_PIPELINE;

const root = document.getElementById("root");
if (!root) throw new Error("index.html has no #root element");
createRoot(root).render(<App client={client} initialPipeline={initial} />);
