/** The UI protocol over a browser Web Worker (the browser build's engine). */
import type { EngineConnection, EngineMessage, UiMessage } from "../engine/protocol";

export function workerConnection(url: URL): EngineConnection {
  const worker = new Worker(url, { type: "module", name: "mosaic-engine" });
  const handlers = new Set<(m: EngineMessage) => void>();
  worker.onmessage = (e: MessageEvent<EngineMessage>) => {
    for (const h of handlers) h(e.data);
  };
  worker.onerror = (e) => {
    const event = {
      t: Date.now() / 1000,
      level: "error" as const,
      block: "engine",
      message: e.message,
    };
    for (const h of handlers) h({ type: "event", event });
  };
  return {
    send: (msg: UiMessage) => worker.postMessage(msg),
    onMessage(handler) {
      handlers.add(handler);
      return () => handlers.delete(handler);
    },
    close: () => worker.terminate(),
  };
}
