/**
 * One window's link to the session hub: what the renderer sends over IPC goes to the hub (which
 * validates it against the protocol), what the hub sends goes back to the renderer. One hub
 * connection per window page: when the page says `hello` a second time (View → Reload, a crashed
 * renderer that came back) the old connection is closed first, so the old page's panel watches
 * end. The link also notes the pipeline the page loads (the `load` request whose reply is ok),
 * for File → Save Pipeline As…. Plain TypeScript over the hub's interface: tested with a fake hub.
 */
import type { HubClient, HubConnection } from "../host/session-hub";

/** An engine message, as the hub sends it. */
export type HostMessage = Parameters<HubClient["send"]>[0];

export interface LoadedPipeline {
  file: string;
  source: string;
}

export interface HubLike {
  connect(sink: HubClient): HubConnection;
}

export interface WindowLink {
  /** A message from the renderer (already checked to come from our window). */
  receive(raw: unknown): void;
  /** The window closed. */
  close(): void;
}

interface LoadRequest {
  type: "load";
  id: number;
  file: string;
  source: string;
}

function isLoadRequest(raw: unknown): raw is LoadRequest {
  if (raw === null || typeof raw !== "object") return false;
  const m = raw as Record<string, unknown>;
  return (
    m.type === "load" &&
    typeof m.id === "number" &&
    typeof m.file === "string" &&
    typeof m.source === "string"
  );
}

function isHello(raw: unknown): boolean {
  return raw !== null && typeof raw === "object" && (raw as { type?: unknown }).type === "hello";
}

export function createWindowLink(
  hub: HubLike,
  toRenderer: (msg: HostMessage) => void,
  onLoaded?: (p: LoadedPipeline) => void,
): WindowLink {
  let conn: HubConnection | undefined;
  /** Which connection is current: messages of an older one are dropped. */
  let generation = 0;
  let greeted = false;
  let closed = false;
  /** Loads in flight from the current page, by request id (a page sends a few at most). */
  let loads = new Map<number, LoadedPipeline>();

  const open = (): HubConnection => {
    const pageLoads = new Map<number, LoadedPipeline>();
    loads = pageLoads;
    const mine = ++generation;
    return hub.connect({
      send(msg) {
        if (closed || mine !== generation) return;
        if (msg.type === "reply") {
          const load = pageLoads.get(msg.id);
          if (load) {
            pageLoads.delete(msg.id);
            if (msg.ok) onLoaded?.(load);
          }
        }
        toRenderer(msg);
      },
    });
  };

  return {
    receive(raw) {
      if (closed) return;
      if (isHello(raw)) {
        // A new page in the same window: start over with a fresh connection.
        if (greeted && conn) {
          generation++;
          conn.close();
          conn = undefined;
        }
        greeted = true;
      }
      conn ??= open();
      if (isLoadRequest(raw)) {
        if (loads.size > 16) loads.clear();
        loads.set(raw.id, { file: raw.file, source: raw.source });
      }
      conn.receive(raw);
    },
    close() {
      if (closed) return;
      closed = true;
      conn?.close();
      conn = undefined;
    },
  };
}
