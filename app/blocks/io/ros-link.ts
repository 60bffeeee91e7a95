/**
 * The ROS block's link to rosbridge: connects, advertises or subscribes, and when the connection
 * is refused or lost waits ReconnectSeconds (doubling after each failure, up to
 * ReconnectMaxSeconds) before the next attempt (the behaviour is described in the block's help,
 * ros.ts).
 */
import {
  errorMessage,
  type BlockContext,
  type RosBridge,
  type RosConnection,
  type RosConnectionState,
  type RosPublisher,
  type RosSubscription,
} from "../../engine";
import type { RosMessageType } from "./ros-messages";
import type { WarnLimiter } from "./udp-common";

export type RosLinkState =
  "idle" | "unavailable" | "connecting" | "connected" | "waiting" | "stopped";

/** What the block's params say about the link. */
export interface RosLinkOptions {
  url: string;
  topic: string;
  type: RosMessageType;
  publish: boolean;
  latch: boolean | undefined;
  throttleMs: number | undefined;
  queueLength: number | undefined;
  reconnectSeconds: number;
  reconnectMaxSeconds: number;
}

/** What the link tells the block: its state changed; a message arrived (subscribe). */
export interface RosLinkHooks {
  changed(): void;
  message(msg: unknown): void;
}

export class RosLink {
  state: RosLinkState;
  /** Why the last connection failed or was lost. */
  reason = "";
  /** Failed attempts (or lost connections) since the last successful connection. */
  failures = 0;
  connections = 0;
  retryAt = Infinity;
  running = false;
  private conn: RosConnection | undefined;
  private pub: RosPublisher | undefined;
  private sub: RosSubscription | undefined;
  /** Each connection attempt gets a number; callbacks of older attempts are ignored. */
  private attempt = 0;

  constructor(
    private readonly ctx: BlockContext,
    private readonly bridge: RosBridge | undefined,
    private readonly o: RosLinkOptions,
    private readonly warns: WarnLimiter,
    private readonly hooks: RosLinkHooks,
  ) {
    this.state = bridge ? "idle" : "unavailable";
  }

  /** The publisher while advertised (it may be set before the connection is up). */
  get publisher(): RosPublisher | undefined {
    return this.pub;
  }

  start(): void {
    if (this.running) return;
    this.running = true;
    this.failures = 0;
    this.connect();
  }

  stop(): void {
    this.end();
    if (this.state !== "unavailable") this.state = "stopped";
    this.retryAt = Infinity;
  }

  /** Ends the run: callbacks of the current attempt are ignored from now on. */
  end(): void {
    this.running = false;
    this.attempt++;
    this.closeConnection();
  }

  /** Counts from now on: the connection that is up (if any) is the first. */
  resetConnections(): void {
    this.connections = this.state === "connected" ? 1 : 0;
  }

  private current(id: number): boolean {
    return id === this.attempt && this.running;
  }

  private closeConnection(): void {
    const c = this.conn;
    const s = this.sub;
    const pb = this.pub;
    this.conn = undefined;
    this.sub = undefined;
    this.pub = undefined;
    try {
      s?.unsubscribe();
      pb?.unadvertise();
      c?.close();
    } catch (e) {
      this.warns.warn(`closing the connection to ${this.o.url}: ${errorMessage(e)}`);
    }
  }

  /** The one-shot: refreshes the countdown every second and reconnects when it is due. */
  private readonly countdown = (): void => {
    if (!this.running || this.state !== "waiting") return;
    const now = this.ctx.now();
    if (now >= this.retryAt - 1e-6) {
      this.connect();
      return;
    }
    this.hooks.changed();
    this.ctx.at(Math.min(this.retryAt, now + 1), this.countdown);
  };

  private lost(message: string): void {
    const wasConnected = this.state === "connected";
    this.closeConnection();
    this.reason = message;
    this.failures++;
    this.state = "waiting";
    this.scheduleRetry();
    const url = this.o.url;
    if (wasConnected) this.warns.warn(`lost the connection to rosbridge at ${url}: ${message}`);
    else if (this.failures === 1) {
      this.warns.warn(`cannot connect to rosbridge at ${url}: ${message}`);
    }
    this.hooks.changed();
  }

  private scheduleRetry(): void {
    const { reconnectSeconds, reconnectMaxSeconds } = this.o;
    if (reconnectSeconds > 0) {
      const wait = Math.min(reconnectMaxSeconds, reconnectSeconds * 2 ** (this.failures - 1));
      this.retryAt = this.ctx.now() + wait;
      this.ctx.at(Math.min(this.retryAt, this.ctx.now() + 1), this.countdown);
    } else {
      this.retryAt = Infinity;
    }
  }

  private onState(id: number, s: RosConnectionState, message?: string): void {
    if (!this.current(id)) return;
    if (s === "connecting") {
      this.state = "connecting";
    } else if (s === "connected") {
      this.state = "connected";
      this.failures = 0;
      this.connections++;
      this.reason = "";
    } else {
      this.lost(message ?? "closed");
      return;
    }
    this.hooks.changed();
  }

  private connect(): void {
    const bridge = this.bridge;
    if (!bridge) return;
    const id = ++this.attempt;
    this.state = "connecting";
    this.hooks.changed();
    const { url, topic } = this.o;
    let c: RosConnection;
    try {
      c = bridge.connect({
        url,
        onState: (s, message) => this.onState(id, s, message),
        onNotice: (m) => {
          if (this.current(id)) this.warns.warn(`rosbridge ${url} (${topic}): ${m}`);
        },
      });
    } catch (e) {
      this.lost(errorMessage(e));
      return;
    }
    if (!this.current(id) || (this.state as RosLinkState) === "waiting") {
      // Refused at once (through onState): this attempt is over.
      try {
        c.close();
      } catch {
        // nothing to close
      }
      return;
    }
    this.conn = c;
    try {
      this.join(c);
    } catch (e) {
      if (this.current(id)) this.lost(errorMessage(e));
    }
  }

  /** Advertises the topic (publish) or subscribes to it. */
  private join(c: RosConnection): void {
    const { topic, type, latch, throttleMs, queueLength } = this.o;
    if (this.o.publish) {
      this.pub = c.advertise({ topic, type, ...(latch !== undefined ? { latch } : {}) });
    } else {
      this.sub = c.subscribe({
        topic,
        type,
        ...(throttleMs !== undefined ? { throttleMs } : {}),
        ...(queueLength !== undefined ? { queueLength } : {}),
        onMessage: this.hooks.message,
      });
    }
  }
}
