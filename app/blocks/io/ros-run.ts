/**
 * One ROS block at run time: publishes its input events through the link to rosbridge, or emits
 * the messages the link receives as events; counts what was sent, received, dropped, skipped and
 * malformed, and says it in the status (the behaviour is described in the block's help, ros.ts).
 */
import type { BlockContext, BlockInstance, Frame, OutputPort } from "../../engine";
import { formatCount, plural, TextThrottle } from "../shared/text";
import { RosLink, type RosLinkOptions, type RosLinkState } from "./ros-link";
import type { RosDecoder, RosEncoder } from "./ros-messages";
import { WarnLimiter } from "./udp-common";

/** The publishing side (an encoder) or the subscribing side (a decoder and the output). */
export type RosSide =
  | { publish: true; size: number; encoder: RosEncoder }
  | { publish: false; size: number; decoder: RosDecoder; out: OutputPort };

const UNAVAILABLE =
  "ROS is unavailable here (the browser build has no rosbridge connection): run the " +
  "pipeline with the desktop app or `mosaic run`";

/** "0.3 s", "12 s". */
const seconds = (s: number): string =>
  s < 1 ? `${Math.max(0.1, Math.ceil(s * 10) / 10)} s` : `${Math.ceil(s - 1e-9)} s`;

export class RosRun {
  private readonly link: RosLink;
  private readonly warns: WarnLimiter;
  private readonly throttle = new TextThrottle();
  private readonly scratch: Float64Array;
  private readonly hasBridge: boolean;
  private sent = 0;
  private received = 0;
  private dropped = 0;
  private skipped = 0;
  private malformed = 0;
  private lastMalformed = "";
  private lastText = "";

  constructor(
    private readonly ctx: BlockContext,
    private readonly side: RosSide,
    private readonly o: RosLinkOptions,
  ) {
    this.warns = new WarnLimiter(ctx);
    this.scratch = new Float64Array(side.size);
    const bridge = ctx.io.ros;
    this.hasBridge = bridge !== undefined;
    this.link = new RosLink(ctx, bridge, o, this.warns, {
      changed: () => this.describe(),
      message: (msg) => this.onMessage(msg),
    });
    this.describe();
  }

  instance(): BlockInstance {
    return {
      start: () => this.start(),
      process: (f: Frame) => this.process(f),
      stop: () => {
        this.link.stop();
        this.describe();
      },
      reset: () => this.reset(),
      dispose: () => this.link.end(),
      actions: {
        counts: {
          label: "Counts",
          description:
            "Messages sent or received, dropped while disconnected, malformed, reconnects",
          run: () => this.counts(),
        },
      },
    };
  }

  private start(): void {
    if (!this.hasBridge) {
      this.ctx.warn(
        "ROS is unavailable here (the browser build has no rosbridge connection): this block " +
          (this.o.publish ? "sends nothing" : "receives nothing"),
      );
      this.describe();
      return;
    }
    this.link.start();
  }

  /** Publishes every event with finite values while connected; counts the others. */
  private process(f: Frame): void {
    const n = f.n;
    const side = this.side;
    if (n === 0 || !side.publish) return;
    const encoder = side.encoder;
    const size = side.size;
    const v = f.v;
    const stride = f.stride;
    const p0 = this.link.publisher;
    const live = p0 !== undefined && this.link.state === "connected";
    for (let e = 0; e < n; e++) {
      const off = e * stride;
      if (!live) {
        this.dropped++;
        continue;
      }
      let finite = true;
      for (let k = 0; k < size; k++) {
        if (!Number.isFinite(v[off + k]!)) {
          finite = false;
          break;
        }
      }
      if (!finite) {
        this.skipped++;
        continue;
      }
      if (p0.publish(encoder.encode(v, off))) this.sent++;
      else this.dropped++;
    }
    if (this.throttle.due(f.t[n - 1]!)) this.describe();
  }

  /** A message on the subscribed topic: one event stamped with its arrival, or malformed. */
  private onMessage(msg: unknown): void {
    const side = this.side;
    if (!this.link.running || side.publish) return;
    const now = this.ctx.now();
    const err = side.decoder.decode(msg, this.scratch);
    if (err !== undefined) {
      this.malformed++;
      this.lastMalformed = err;
      this.warns.warn(
        `malformed ${this.o.type} message on ${this.o.topic}: ${err} (${this.malformed} so far)`,
      );
      this.describe();
      return;
    }
    const f = side.out.frame(1);
    f.t[0] = now;
    f.v.set(this.scratch);
    this.received++;
    side.out.emit(f);
    if (this.throttle.due(now)) this.describe();
  }

  private reset(): void {
    this.sent = 0;
    this.received = 0;
    this.dropped = 0;
    this.skipped = 0;
    this.malformed = 0;
    this.lastMalformed = "";
    this.link.resetConnections();
    this.throttle.reset();
    this.warns.reset();
    this.describe();
  }

  private counts(): string {
    const { link, lastMalformed } = this;
    return (
      `${link.state}: ${this.sent} sent, ${this.received} received, ${this.dropped} dropped while disconnected, ` +
      `${this.skipped} not sent (NaN or ±∞), ${this.malformed} malformed` +
      `${lastMalformed ? ` (last: ${lastMalformed})` : ""}, ${Math.max(0, link.connections - 1)} reconnects`
    );
  }

  private describe(): void {
    const state = this.link.state;
    const text = state === "unavailable" ? this.unavailableText() : this.statusText(state);
    if (text !== this.lastText) this.ctx.setText((this.lastText = text));
  }

  private unavailableText(): string {
    return this.dropped > 0
      ? `${UNAVAILABLE} · ${formatCount(this.dropped)} not sent`
      : UNAVAILABLE;
  }

  /** The link's state, what the block does, then its counts. */
  private statusText(state: Exclude<RosLinkState, "unavailable">): string {
    const { url, topic, type, publish } = this.o;
    const what = `${publish ? "publishing" : "subscribed to"} ${topic} (${type})`;
    let text = `${this.stateText(state, url)} · ${what}`;
    text += publish ? ` · ${formatCount(this.sent)} out` : ` · ${formatCount(this.received)} in`;
    const connections = this.link.connections;
    if (connections > 1) text += ` · ${plural(connections - 1, "reconnect")}`;
    if (this.dropped > 0) text += ` · ${formatCount(this.dropped)} dropped while disconnected`;
    if (this.skipped > 0) text += ` · ${formatCount(this.skipped)} not sent (NaN or ±∞)`;
    if (this.malformed > 0) {
      text += ` · ${formatCount(this.malformed)} malformed (last: ${this.lastMalformed})`;
    }
    return text;
  }

  private stateText(state: Exclude<RosLinkState, "unavailable">, url: string): string {
    const link = this.link;
    switch (state) {
      case "idle":
        return url;
      case "connecting":
        return `connecting to ${url}${link.failures > 0 ? ` (attempt ${link.failures + 1})` : ""}…`;
      case "connected":
        return `connected to ${url}`;
      case "waiting": {
        const wait =
          link.retryAt === Infinity
            ? "not reconnecting (ReconnectSeconds 0)"
            : `reconnecting in ${seconds(link.retryAt - this.ctx.now())} (attempt ${link.failures + 1})`;
        return `disconnected from ${url}: ${link.reason}; ${wait}`;
      }
      case "stopped":
        return "stopped";
    }
  }
}
