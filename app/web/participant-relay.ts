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
  const relay = new ParticipantRelay(client, channel);
  channel.addEventListener("message", (e) => relay.receive(e.data));
  const offs = relay.followClient();
  // Participant windows opened before this page (or before it reloaded) say hello again.
  channel.postMessage({ relayUp: true } satisfies FromRelay);
  return () => {
    for (const off of offs) off();
    relay.dropAll();
    channel.postMessage({ relayDown: true } satisfies FromRelay);
    channel.close();
  };
}

type WatchMessage = Extract<UiMessage, { type: "watch" | "unwatch" }>;

/** The clinician side's state: who said hello, what each watches, and how to answer them. */
class ParticipantRelay {
  /** Participants that said hello, with the watches each holds (key → stop). */
  private readonly participants = new Map<string, Map<string, () => void>>();

  constructor(
    private readonly client: EngineClient,
    private readonly channel: ChannelLike,
  ) {}

  /** One message from the channel: a participant's protocol message or goodbye. */
  receive(data: unknown): void {
    const m = asToRelay(data);
    if (!m) return;
    if ("bye" in m) this.drop(m.from);
    else this.handle(m.from, m.msg);
  }

  /** Passes the clinician client's hello, state, telemetry and graph on to every participant. */
  followClient(): (() => void)[] {
    const { client } = this;
    return [
      client.onHello(() => this.everyone(this.hello())),
      client.onState((state) => this.everyone({ type: "state", state })),
      client.onTelemetry((telemetry) => this.everyone({ type: "telemetry", telemetry })),
      client.onGraph((graph: GraphInfo | undefined) => {
        if (graph) this.everyone({ type: "graph", graph });
      }),
    ];
  }

  /** Forgets every participant, stopping their watches. */
  dropAll(): void {
    for (const from of [...this.participants.keys()]) this.drop(from);
  }

  private post(to: string, msg: EngineMessage): void {
    this.channel.postMessage({ to, msg } satisfies FromRelay);
  }

  private everyone(msg: EngineMessage): void {
    if (this.participants.size > 0) this.post("*", msg);
  }

  private hello(): EngineMessage {
    return {
      type: "hello",
      version: PROTOCOL_VERSION,
      engine: this.client.engineName,
      sharedMemory: this.client.sharedMemory,
    };
  }

  /** (Re)admits a participant and sends it what `mosaic serve` sends a tab that joins. */
  private greet(from: string): void {
    const { client } = this;
    this.drop(from);
    this.participants.set(from, new Map());
    this.post(from, this.hello());
    if (client.graph) this.post(from, { type: "graph", graph: client.graph });
    this.post(from, { type: "state", state: client.state });
    if (client.telemetry) this.post(from, { type: "telemetry", telemetry: client.telemetry });
  }

  private drop(from: string): void {
    for (const off of this.participants.get(from)?.values() ?? []) off();
    this.participants.delete(from);
  }

  private reply(to: string, id: number, ok: boolean, message?: string): void {
    this.post(to, { type: "reply", id, ok, ...(message !== undefined ? { message } : {}) });
  }

  /** A participant's protocol message: hello, watch and unwatch are answered, the rest refused. */
  private handle(from: string, msg: UiMessage): void {
    if (msg.type === "hello") return this.greet(from);
    const mine = this.participants.get(from);
    if (!("id" in msg)) return;
    if (!mine) return this.reply(from, msg.id, false, "say hello first");
    if (msg.type === "watch" || msg.type === "unwatch") return this.watch(from, mine, msg);
    this.reply(from, msg.id, false, "the participant window only shows the session");
  }

  /** Replaces (watch) or stops (unwatch) the participant's watch of one block's port. */
  private watch(from: string, mine: Map<string, () => void>, msg: WatchMessage): void {
    const key = `${msg.block}\u0000${msg.port ?? ""}`;
    mine.get(key)?.();
    mine.delete(key);
    if (msg.type === "watch") {
      mine.set(
        key,
        this.client.watch(msg.block, msg.port, (m) => this.post(from, m), msg.maxRate),
      );
    }
    this.reply(from, msg.id, true);
  }
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
