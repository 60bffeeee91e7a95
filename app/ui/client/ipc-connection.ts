/**
 * The UI protocol over Electron IPC: the desktop app's preload exposes `window.mosaicHost`
 * (app/electron/preload.ts) with `send`, `onMessage` and `version`; messages are structured
 * clones, so typed arrays (panel data) arrive as they are. The engine runs in the main process's
 * session hub, one connection per window.
 */
import type { EngineConnection, EngineMessage, UiMessage } from "../../engine/protocol";

/** What the desktop preload exposes as `window.mosaicHost`. */
export interface MosaicHost {
  readonly version?: number;
  send(msg: UiMessage): void;
  onMessage(callback: (msg: EngineMessage) => void): () => void;
}

/** The desktop host of this page (`globalThis.mosaicHost`), or undefined in a browser. */
export function desktopHost(scope: unknown = globalThis): MosaicHost | undefined {
  const host = (scope as { mosaicHost?: unknown } | null | undefined)?.mosaicHost;
  if (host === null || typeof host !== "object") return undefined;
  const h = host as Partial<MosaicHost>;
  return typeof h.send === "function" && typeof h.onMessage === "function"
    ? (host as MosaicHost)
    : undefined;
}

export function ipcConnection(host: MosaicHost): EngineConnection {
  const handlers = new Set<(m: EngineMessage) => void>();
  let closed = false;
  const off = host.onMessage((m) => {
    if (closed) return;
    for (const h of handlers) h(m);
  });
  return {
    send(msg: UiMessage) {
      if (closed) return;
      try {
        host.send(msg);
      } catch (e) {
        // Not cloneable, or the host is gone: tell the UI like any engine error.
        const event = {
          t: Date.now() / 1000,
          level: "error" as const,
          block: "engine",
          message: `cannot send '${msg.type}' to the MOSAIC host: ${(e as Error).message}`,
        };
        for (const h of handlers) h({ type: "event", event });
      }
    },
    onMessage(handler) {
      handlers.add(handler);
      return () => handlers.delete(handler);
    },
    close() {
      if (closed) return;
      closed = true;
      off();
      handlers.clear();
    },
  };
}
