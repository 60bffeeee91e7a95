/**
 * One UdpReceiver at run time: listens on its port, decodes every datagram into events, counts
 * what was lost, out of order, ignored or malformed, and shows it in the status (the behaviour is
 * described in the block's help, udp-receiver.ts).
 */
import type {
  BlockContext,
  BlockInstance,
  Endpoint,
  OutputPort,
  UdpBridge,
  UdpSocketHandle,
} from "../../engine";
import { plural, TextThrottle } from "../shared/text";
import {
  counterGap,
  decodeRaw,
  decodeStreamlined,
  MAX_DATAGRAM_BYTES,
  MAX_STREAMLINED_VALUES,
  newHeader,
  valueSize,
} from "./udp-format";
import { endpointText, WarnLimiter, NO_UDP } from "./udp-common";

/** What the block's params decide (checked by the block before the run starts). */
export interface UdpReceiverSettings {
  host: string;
  port: number;
  /** Format streamlined; otherwise `raw` vectors. */
  streamlined: boolean;
  raw: "f32" | "f64";
  channels: number;
  category: number | undefined;
  subcategory: number | undefined;
  /** Timestamps "sender": the streamlined timestamp instead of the arrival time. */
  senderTime: boolean;
  scale: number;
}

export class UdpReceiverRun {
  private readonly where: string;
  private readonly header = newHeader();
  /** Raw formats: the most whole vectors one datagram holds. */
  private readonly maxVectors: number;
  private readonly scratch: Float64Array;
  private readonly warns: WarnLimiter;
  private readonly throttle = new TextThrottle(0.25);

  private socket: UdpSocketHandle | undefined;
  private listening = false;
  private state: "opening" | "listening" | "closed" = "opening";
  /** Could not bind: the status says why. */
  private failure = "";
  private readonly counts = {
    datagrams: 0,
    events: 0,
    malformed: 0,
    ignored: 0,
    lost: 0,
    reordered: 0,
  };
  private lastMalformed = "";
  private lastCounter = -1;
  private lastT = -Infinity;

  constructor(
    private readonly ctx: BlockContext,
    private readonly s: UdpReceiverSettings,
    private readonly out: OutputPort,
    /** Undefined: UDP is unavailable here (udpBridge has said so in the status). */
    private readonly bridge: UdpBridge | undefined,
  ) {
    this.where = endpointText(s.host, s.port);
    this.maxVectors = s.streamlined
      ? 1
      : Math.max(1, Math.floor(MAX_DATAGRAM_BYTES / (s.channels * valueSize(s.raw))));
    this.scratch = new Float64Array(
      s.streamlined ? MAX_STREAMLINED_VALUES : this.maxVectors * s.channels,
    );
    this.warns = new WarnLimiter(ctx);
    if (bridge) this.describe();
  }

  instance(): BlockInstance {
    return {
      start: () => this.start(),
      stop: () => this.stop(),
      reset: () => this.reset(),
      dispose: () => this.dispose(),
      actions: {
        counts: {
          label: "Counts",
          description: "Datagrams received, events emitted, lost, out of order, ignored, malformed",
          run: () => this.countsText(),
        },
      },
    };
  }

  private start(): void {
    const bridge = this.bridge;
    if (!bridge) {
      this.ctx.warn(`${NO_UDP}: this block receives nothing`);
      return;
    }
    if (this.socket) return;
    this.failure = "";
    this.state = "opening";
    try {
      const s = bridge.open({
        bind: { host: this.s.host, port: this.s.port },
        onMessage: this.onMessage,
        onReady: () => {
          this.listening = true;
          this.state = "listening";
          this.describe();
        },
        onError: this.onError,
      });
      // A bridge may refuse at once (through onError) and still return a handle.
      if (this.failure === "") this.socket = s;
      else s.close();
    } catch (e) {
      this.onError(e instanceof Error ? e.message : String(e));
    }
  }

  private stop(): void {
    const s = this.socket;
    this.socket = undefined;
    this.listening = false;
    if (s) this.state = "closed";
    s?.close();
    if (this.bridge && this.failure === "") this.describe();
  }

  private reset(): void {
    const c = this.counts;
    c.datagrams = 0;
    c.events = 0;
    c.malformed = 0;
    this.lastMalformed = "";
    c.ignored = 0;
    c.lost = 0;
    c.reordered = 0;
    this.lastCounter = -1;
    this.lastT = -Infinity;
    this.warns.reset();
    if (this.bridge) this.describe();
  }

  private dispose(): void {
    const s = this.socket;
    this.socket = undefined;
    this.listening = false;
    s?.close();
  }

  private readonly onMessage = (data: Uint8Array, from: Endpoint): void => {
    this.counts.datagrams++;
    const now = this.ctx.now();
    const ok = this.s.streamlined
      ? this.onStreamlined(data, from, now)
      : this.onRaw(data, from, now);
    if (ok && this.throttle.due(now)) this.describe();
  };

  /** One streamlined datagram: one event, or counted as ignored; false when malformed. */
  private onStreamlined(data: Uint8Array, from: Endpoint, now: number): boolean {
    const { header, scratch, s } = this;
    const channels = s.channels;
    const err = decodeStreamlined(data, header, scratch, 0, MAX_STREAMLINED_VALUES, s.scale);
    if (err !== undefined) return this.refuse(err, from);
    if (
      (s.category !== undefined && header.category !== s.category) ||
      (s.subcategory !== undefined && header.subcategory !== s.subcategory)
    ) {
      this.counts.ignored++;
      return true;
    }
    if (header.count !== channels) {
      return this.refuse(`${header.count} values, expected Channels ${channels}`, from);
    }
    this.countGap(header.counter);
    const f = this.out.frame(1);
    f.t[0] = s.senderTime ? header.timestamp : now;
    const v = f.v;
    for (let i = 0; i < channels; i++) v[i] = scratch[i]!;
    this.counts.events++;
    this.out.emit(f);
    return true;
  }

  /** The streamlined counter: datagrams lost or out of order since the last one. */
  private countGap(counter: number): void {
    if (this.lastCounter >= 0) {
      const gap = counterGap(this.lastCounter, counter);
      if (gap > 0) this.counts.lost += gap;
      else if (gap < 0) this.counts.reordered++;
    }
    this.lastCounter = counter;
  }

  /** One raw datagram: its whole vectors, spaced by 1/DesiredRate; false when malformed. */
  private onRaw(data: Uint8Array, from: Endpoint, now: number): boolean {
    const { scratch, s } = this;
    const k = decodeRaw(data, s.raw, s.channels, scratch, this.maxVectors, s.scale);
    if (typeof k === "string") return this.refuse(k, from);
    const f = this.out.frame(k);
    const rate = this.ctx.desiredRate;
    for (let i = 0; i < k; i++) {
      let t = rate > 0 ? now - (k - 1 - i) / rate : now;
      if (t < this.lastT) t = this.lastT;
      f.t[i] = t;
      this.lastT = t;
    }
    const v = f.v;
    for (let i = 0, n = k * s.channels; i < n; i++) v[i] = scratch[i]!;
    this.counts.events += k;
    this.out.emit(f);
    return true;
  }

  /** Counts a malformed datagram and says so; returns false (the datagram gave no event). */
  private refuse(reason: string, from: Endpoint): false {
    const m = ++this.counts.malformed;
    this.lastMalformed = reason;
    this.warns.warn(
      `malformed datagram from ${endpointText(from.host, from.port)} on ${this.where}: ${reason} (${m} so far)`,
    );
    this.describe();
    return false;
  }

  private readonly onError = (message: string): void => {
    if (!this.listening) {
      // Could not bind: this block stays silent, the rest of the pipeline runs on.
      this.failure = `cannot listen on UDP ${this.where}: ${message}`;
      const s = this.socket;
      this.socket = undefined;
      s?.close();
    }
    this.warns.warn(this.listening ? `UDP ${this.where}: ${message}` : this.failure);
    this.describe();
  };

  private describe(): void {
    if (this.failure !== "") {
      this.ctx.setText(this.failure);
      return;
    }
    const { datagrams, lost, reordered, ignored, malformed } = this.counts;
    const where = this.where;
    const parts = [
      this.state === "listening"
        ? `listening on ${where}`
        : this.state === "closed"
          ? `closed ${where}`
          : `opening ${where}`,
      `${plural(datagrams, "datagram")}`,
    ];
    if (lost > 0) parts.push(`${lost} lost`);
    if (reordered > 0) parts.push(`${reordered} out of order`);
    if (ignored > 0) parts.push(`${ignored} ignored (other category)`);
    if (malformed > 0) parts.push(`${malformed} malformed (last: ${this.lastMalformed})`);
    this.ctx.setText(parts.join(", "));
  }

  private countsText(): string {
    const { datagrams, events, lost, reordered, ignored, malformed } = this.counts;
    const last = this.lastMalformed;
    return (
      `${datagrams} datagrams, ${events} events, ${lost} lost, ${reordered} out of order, ` +
      `${ignored} ignored, ${malformed} malformed${last ? ` (last: ${last})` : ""}`
    );
  }
}
