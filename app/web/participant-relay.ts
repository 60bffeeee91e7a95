/**
 * The browser build's participant window, driven by the clinician page's engine (no second
 * engine): the clinician's page runs the engine in its Web Worker and lends it over a
 * BroadcastChannel (same origin: a window it opened, or the same URL in another tab or on
 * another screen). The participant page's EngineClient speaks the UI protocol over
 * `relayConnection`; `startParticipantRelay` answers it through the clinician's own EngineClient:
 * `hello` (with the graph and the state, as `mosaic serve` greets a tab that joins), `watch` and
 * `unwatch` (shared with the clinician's panels by EngineClient.watch, so a participant leaving
 * never stops a clinician's panel), and telemetry, state and graph changes for everyone. Any
 * other request is refused: the participant window shows, it does not control.
 */
import {
  PROTOCOL_VERSION,
  type EngineMessage,
  type GraphInfo,
  type UiMessage,
} from "../engine/protocol";
import type { EngineConnection } from "../engine/protocol";
import type { EngineClient } from "../ui/client/engine-client";

/** What the relay needs of a BroadcastChannel (the DOM's and Node's both have it). */
export interface ChannelLike {
  postMessage(message: unknown): void;
  addEventListener(type: "message", listener: (e: { data: unknown }) => void): void;
  close(): void;
}

export const relayChannelName = (id: string): string => `mosaic-participant:${id}`;

export function openChannel(id: string): ChannelLike {
  return new BroadcastChannel(relayChannelName(id)) as unknown as ChannelLike;
}

/** Participant → clinician: a protocol message, or goodbye (the window closes). */
type ToRelay = { from: string; msg: UiMessage } | { from: string; bye: true };
/**
 * Clinician → participants: an engine message for one (`to`) or all ("*"), or the relay coming
 * up (the clinician's page (re)loaded) or going down (it is closing or reloading).
 */
type FromRelay = { to: string; msg: EngineMessage } | { relayUp: true } | { relayDown: true };

const isRecord = (v: unknown): v is Record<string, unknown> =>
  v !== null && typeof v === "object" && !Array.isArray(v);

function asToRelay(d: unknown): ToRelay | undefined {
  if (!isRecord(d) || typeof d.from !== "string") return undefined;
  if (d.bye === true) return { from: d.from, bye: true };
  return isRecord(d.msg) && typeof d.msg.type === "string"
    ? { from: d.from, msg: d.msg as UiMessage }
    : undefined;
}

/** Lends `client`'s engine to participant windows on channel `id`; returns the stop function. */
export function startParticipantRelay(client: EngineClient, channel: ChannelLike): () => void {
  /** Participants that said hello, with the watches each holds (key → stop). */
  const participants = new Map<string, Map<string, () => void>>();
  const post = (to: string, msg: EngineMessage): void =>
    channel.postMessage({ to, msg } satisfies FromRelay);
  const everyone = (msg: EngineMessage): void => {
    if (participants.size > 0) post("*", msg);
  };
  const hello = (): EngineMessage => ({
    type: "hello",
    version: PROTOCOL_VERSION,
    engine: client.engineName,
    sharedMemory: client.sharedMemory,
  });

  const greet = (from: string): void => {
    drop(from);
    participants.set(from, new Map());
    post(from, hello());
    if (client.graph) post(from, { type: "graph", graph: client.graph });
    post(from, { type: "state", state: client.state });
    if (client.telemetry) post(from, { type: "telemetry", telemetry: client.telemetry });
  };
  const drop = (from: string): void => {
    for (const off of participants.get(from)?.values() ?? []) off();
    participants.delete(from);
  };
  const reply = (to: string, id: number, ok: boolean, message?: string): void =>
    post(to, { type: "reply", id, ok, ...(message !== undefined ? { message } : {}) });

  const handle = (from: string, msg: UiMessage): void => {
    if (msg.type === "hello") return greet(from);
    const mine = participants.get(from);
    if (!("id" in msg)) return;
    if (!mine) return reply(from, msg.id, false, "say hello first");
    if (msg.type === "watch" || msg.type === "unwatch") {
      const key = `${msg.block}\u0000${msg.port ?? ""}`;
      mine.get(key)?.();
      mine.delete(key);
      if (msg.type === "watch") {
        mine.set(
          key,
          client.watch(msg.block, msg.port, (m) => post(from, m), msg.maxRate),
        );
      }
      return reply(from, msg.id, true);
    }
    reply(from, msg.id, false, "the participant window only shows the session");
  };

  const listener = (e: { data: unknown }): void => {
    const m = asToRelay(e.data);
    if (!m) return;
    if ("bye" in m) drop(m.from);
    else handle(m.from, m.msg);
  };
  channel.addEventListener("message", listener);
  const offs = [
    client.onHello(() => everyone(hello())),
    client.onState((state) => everyone({ type: "state", state })),
    client.onTelemetry((telemetry) => everyone({ type: "telemetry", telemetry })),
    client.onGraph((graph: GraphInfo | undefined) => {
      if (graph) everyone({ type: "graph", graph });
    }),
  ];
  // Participant windows opened before this page (or before it reloaded) say hello again.
  channel.postMessage({ relayUp: true } satisfies FromRelay);
  return () => {
    for (const off of offs) off();
    for (const from of [...participants.keys()]) drop(from);
    channel.postMessage({ relayDown: true } satisfies FromRelay);
    channel.close();
  };
}

/** The participant side's connection, which also says when the clinician's page comes and goes. */
export interface RelayConnection extends EngineConnection {
  /** `up` false: the clinician's page closed (or is reloading); true: it is back. */
  onLink(listener: (up: boolean) => void): () => void;
}

/**
 * The participant page's side: the UI protocol over the channel, to the clinician page's relay.
 * When the relay (re)starts, the page's hello and watches are sent again.
 */
export function relayConnection(
  channel: ChannelLike,
  me = `p${Math.random().toString(36).slice(2)}`,
): RelayConnection {
  const handlers = new Set<(m: EngineMessage) => void>();
  const links = new Set<(up: boolean) => void>();
  let hello: UiMessage | undefined;
  const watches = new Map<string, UiMessage>();
  const send = (msg: UiMessage): void => channel.postMessage({ from: me, msg } satisfies ToRelay);
  channel.addEventListener("message", (e) => {
    const d = e.data;
    if (!isRecord(d)) return;
    if (d.relayUp === true) {
      if (hello) send(hello);
      for (const w of watches.values()) send(w);
      for (const l of links) l(true);
      return;
    }
    if (d.relayDown === true) {
      for (const l of links) l(false);
      return;
    }
    if ((d.to === me || d.to === "*") && isRecord(d.msg)) {
      for (const h of handlers) h(d.msg as EngineMessage);
    }
  });
  let closed = false;
  return {
    send(msg) {
      if (closed) return;
      if (msg.type === "hello") hello = msg;
      if (msg.type === "watch") watches.set(`${msg.block}\u0000${msg.port ?? ""}`, msg);
      if (msg.type === "unwatch") watches.delete(`${msg.block}\u0000${msg.port ?? ""}`);
      send(msg);
    },
    onMessage(handler) {
      handlers.add(handler);
      return () => handlers.delete(handler);
    },
    onLink(listener) {
      links.add(listener);
      return () => links.delete(listener);
    },
    close() {
      if (closed) return;
      closed = true;
      channel.postMessage({ from: me, bye: true } satisfies ToRelay);
      channel.close();
    },
  };
}
