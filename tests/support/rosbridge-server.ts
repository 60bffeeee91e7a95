/**
 * A rosbridge v2 server for tests (no ROS here): the topic part of the protocol
 * (rosbridge_suite's ROSBRIDGE_PROTOCOL.md §3.2.1–3.2.5) over a WebSocket, on the `ws` package.
 *
 * - `advertise` {topic, type, id?}: registers the client as a publisher; a topic keeps the type it
 *   was first given, and another type is refused with a `status` error (as rosbridge does).
 * - `unadvertise` {topic, id?}: unregisters it (a warning status when it was not advertised).
 * - `publish` {topic, msg, id?}: recorded, and routed to every subscription of the topic (the
 *   publisher's own included); refused (error status) when the topic has no type yet or `msg` is
 *   not an object.
 * - `subscribe` {topic, type?, id?, throttle_rate?, queue_length?}: a subscription; without a
 *   type the topic's known type is used (an error when there is none).
 * - `unsubscribe` {topic, id?}: that subscription, or all of the client's on the topic.
 * Any other op, and text that is not a JSON object with `op`, get an error `status`.
 *
 * The test plays the ROS side with `publish(topic, msg)` (a ROS node publishing) and reads what
 * clients sent with `published(topic)`. `stop()` drops every client without a close frame, as a
 * killed rosbridge would; `start(port)` again serves on the same port.
 */
import type { AddressInfo } from "node:net";
import { WebSocketServer, type WebSocket } from "ws";

export interface RosbridgeOp {
  op: string;
  id?: string | number;
  topic?: string;
  type?: string;
  msg?: unknown;
  [k: string]: unknown;
}

interface Subscription {
  client: WebSocket;
  id: string | number | undefined;
  throttleRate: number;
  queueLength: number;
}

export interface PublishedMessage {
  topic: string;
  msg: unknown;
  /** Which connection sent it (1 for the first client of this server, …). */
  client: number;
  /** Date.now() at arrival. */
  at: number;
}

export class RosbridgeTestServer {
  /** Every op received, in arrival order (across restarts). */
  readonly ops: RosbridgeOp[] = [];
  /** Every message clients published, in arrival order (across restarts). */
  readonly messages: PublishedMessage[] = [];
  /** Status messages sent to clients. */
  readonly statuses: RosbridgeOp[] = [];
  private wss: WebSocketServer | undefined;
  private readonly types = new Map<string, string>();
  private readonly subs = new Map<string, Subscription[]>();
  private readonly advertisers = new Map<string, Set<WebSocket>>();
  private readonly clientIds = new Map<WebSocket, number>();
  private nextClient = 1;
  private portNumber = 0;

  /** Starts a server on 127.0.0.1 (port 0: any free port). */
  static async start(port = 0): Promise<RosbridgeTestServer> {
    const s = new RosbridgeTestServer();
    await s.start(port);
    return s;
  }

  get port(): number {
    return this.portNumber;
  }

  get url(): string {
    return `ws://127.0.0.1:${this.portNumber}`;
  }

  get running(): boolean {
    return this.wss !== undefined;
  }

  /** Serves on `port` (again, after `stop`): topic types are kept, clients are new. */
  async start(port = this.portNumber): Promise<void> {
    if (this.wss) throw new Error("the rosbridge test server is already running");
    const wss = new WebSocketServer({ host: "127.0.0.1", port });
    await new Promise<void>((resolve, reject) => {
      wss.once("listening", resolve);
      wss.once("error", reject);
    });
    this.portNumber = (wss.address() as AddressInfo).port;
    wss.on("connection", (ws) => this.accept(ws));
    this.wss = wss;
  }

  /** Drops every client at once (no close frame, like a killed process) and stops listening. */
  async stop(): Promise<void> {
    const wss = this.wss;
    if (!wss) return;
    this.wss = undefined;
    for (const c of wss.clients) c.terminate();
    await new Promise<void>((resolve) => wss.close(() => resolve()));
    this.subs.clear();
    this.advertisers.clear();
  }

  /** Connected clients. */
  get clients(): number {
    return this.wss?.clients.size ?? 0;
  }

  /** Subscriptions to `topic`, over all clients. */
  subscribers(topic: string): number {
    return this.subs.get(topic)?.length ?? 0;
  }

  /** Clients advertising `topic`. */
  publishers(topic: string): number {
    return this.advertisers.get(topic)?.size ?? 0;
  }

  /** The type `topic` was established with. */
  typeOf(topic: string): string | undefined {
    return this.types.get(topic);
  }

  /** The messages clients published on `topic`. */
  published(topic: string): unknown[] {
    return this.messages.filter((m) => m.topic === topic).map((m) => m.msg);
  }

  /**
   * Publishes `msg` on `topic` as a ROS node would: every subscription gets one `publish` op.
   * Returns the number of subscriptions reached.
   */
  publish(topic: string, msg: unknown, type?: string): number {
    if (type !== undefined && !this.types.has(topic)) this.types.set(topic, type);
    const list = this.subs.get(topic) ?? [];
    const text = JSON.stringify({ op: "publish", topic, msg });
    for (const s of list) s.client.send(text);
    return list.length;
  }

  private accept(ws: WebSocket): void {
    const client = this.nextClient++;
    this.clientIds.set(ws, client);
    ws.on("message", (data, isBinary) => {
      if (isBinary) {
        this.status(ws, "error", "binary messages are not supported by this test server");
        return;
      }
      let m: unknown;
      try {
        m = JSON.parse(String(data));
      } catch {
        this.status(ws, "error", `not JSON: ${String(data).slice(0, 80)}`);
        return;
      }
      if (typeof m !== "object" || m === null || typeof (m as RosbridgeOp).op !== "string") {
        this.status(ws, "error", "a rosbridge message is a JSON object with a string `op`");
        return;
      }
      const op = m as RosbridgeOp;
      this.ops.push(op);
      this.handle(ws, client, op);
    });
    ws.on("close", () => this.forget(ws));
    ws.on("error", () => this.forget(ws));
  }

  private forget(ws: WebSocket): void {
    for (const [topic, list] of this.subs) {
      this.subs.set(
        topic,
        list.filter((s) => s.client !== ws),
      );
    }
    for (const set of this.advertisers.values()) set.delete(ws);
    this.clientIds.delete(ws);
  }

  private status(
    ws: WebSocket,
    level: "error" | "warning" | "info",
    msg: string,
    id?: string | number,
  ): void {
    const s: RosbridgeOp = { op: "status", level, msg, ...(id !== undefined ? { id } : {}) };
    this.statuses.push(s);
    if (ws.readyState === ws.OPEN) ws.send(JSON.stringify(s));
  }

  private handle(ws: WebSocket, client: number, m: RosbridgeOp): void {
    const topic = m.topic;
    if (
      ["advertise", "unadvertise", "publish", "subscribe", "unsubscribe"].includes(m.op) &&
      (typeof topic !== "string" || topic === "")
    ) {
      this.status(ws, "error", `${m.op}: missing the field topic`, m.id);
      return;
    }
    const t = topic as string;
    switch (m.op) {
      case "advertise": {
        if (typeof m.type !== "string" || m.type === "") {
          this.status(ws, "error", "advertise: missing the field type", m.id);
          return;
        }
        const known = this.types.get(t);
        if (known !== undefined && known !== m.type) {
          this.status(
            ws,
            "error",
            `advertise: topic ${t} already established with type ${known}, not ${m.type}`,
            m.id,
          );
          return;
        }
        this.types.set(t, m.type);
        let set = this.advertisers.get(t);
        if (!set) this.advertisers.set(t, (set = new Set()));
        set.add(ws);
        return;
      }
      case "unadvertise": {
        const set = this.advertisers.get(t);
        if (!set?.delete(ws)) {
          this.status(ws, "warning", `unadvertise: topic ${t} is not advertised by you`, m.id);
        }
        return;
      }
      case "publish": {
        if (!this.types.has(t)) {
          this.status(ws, "error", `publish: topic ${t} does not exist (advertise it first)`, m.id);
          return;
        }
        if (typeof m.msg !== "object" || m.msg === null || Array.isArray(m.msg)) {
          this.status(ws, "error", `publish: msg is not a message object`, m.id);
          return;
        }
        this.messages.push({ topic: t, msg: m.msg, client, at: Date.now() });
        const text = JSON.stringify({ op: "publish", topic: t, msg: m.msg });
        for (const s of this.subs.get(t) ?? []) s.client.send(text);
        return;
      }
      case "subscribe": {
        const known = this.types.get(t);
        const type = typeof m.type === "string" && m.type !== "" ? m.type : known;
        if (type === undefined) {
          this.status(ws, "error", `subscribe: cannot infer the type of topic ${t}`, m.id);
          return;
        }
        if (known !== undefined && known !== type) {
          this.status(ws, "error", `subscribe: topic ${t} has type ${known}, not ${type}`, m.id);
          return;
        }
        this.types.set(t, type);
        const list = this.subs.get(t) ?? [];
        list.push({
          client: ws,
          id: m.id,
          throttleRate: typeof m.throttle_rate === "number" ? m.throttle_rate : 0,
          queueLength: typeof m.queue_length === "number" ? m.queue_length : 0,
        });
        this.subs.set(t, list);
        return;
      }
      case "unsubscribe": {
        const list = this.subs.get(t) ?? [];
        const keep = list.filter((s) => s.client !== ws || (m.id !== undefined && s.id !== m.id));
        if (keep.length === list.length) {
          this.status(ws, "warning", `unsubscribe: no subscription to ${t} to cancel`, m.id);
        }
        this.subs.set(t, keep);
        return;
      }
      default:
        this.status(ws, "error", `Unknown operation ${JSON.stringify(m.op)}`, m.id);
    }
  }

  /** Subscription options (throttle_rate, queue_length) as received, for `topic`. */
  subscriptionOptions(topic: string): { throttleRate: number; queueLength: number }[] {
    return (this.subs.get(topic) ?? []).map((s) => ({
      throttleRate: s.throttleRate,
      queueLength: s.queueLength,
    }));
  }
}
