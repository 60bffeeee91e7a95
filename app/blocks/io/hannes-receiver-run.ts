/**
 * One HannesReceiver block at run time: listens on its UDP socket, decodes each datagram's EMG
 * values, emits them at once or keeps them for the timer's ticks, and counts what it received,
 * dropped, repeated and could not decode (the behaviour is described in the block's help,
 * hannes-receiver.ts).
 */
import type {
  BlockContext,
  BlockInstance,
  Endpoint,
  Frame,
  OutputPort,
  UdpBridge,
  UdpSocketHandle,
} from "../../engine";
import { plural, TextThrottle } from "../shared/text";
import { decodeHannesEmg } from "./hannes-protocol";
import { endpointText, WarnLimiter, NO_UDP } from "./udp-common";

export interface HannesReceiverOptions {
  host: string;
  port: number;
  channels: number;
  /** Samples kept waiting for ticks. */
  maxDelay: number;
  /** A timer input paces the output. */
  paced: boolean;
}

/** Samples waiting for ticks, oldest first; the `cap` newest are kept. */
class SampleQueue {
  private readonly buf: Float64Array;
  private head = 0;
  private count = 0;

  constructor(
    private readonly cap: number,
    private readonly width: number,
  ) {
    this.buf = new Float64Array(cap * width);
  }

  /** Adds a sample; false when the oldest was dropped to make room. */
  push(v: Float64Array): boolean {
    let kept = true;
    if (this.count === this.cap) {
      // Drop the oldest: keep the MaxDelay newest.
      this.head = (this.head + 1) % this.cap;
      this.count--;
      kept = false;
    }
    this.buf.set(v, ((this.head + this.count) % this.cap) * this.width);
    this.count++;
    return kept;
  }

  /** Moves the oldest sample into `into`; false when none waits. */
  shift(into: Float64Array): boolean {
    if (this.count === 0) return false;
    const C = this.width;
    into.set(this.buf.subarray(this.head * C, (this.head + 1) * C));
    this.head = (this.head + 1) % this.cap;
    this.count--;
    return true;
  }

  clear(): void {
    this.head = 0;
    this.count = 0;
  }
}

export class HannesReceiverRun {
  private readonly where: string;
  private readonly warns: WarnLimiter;
  private readonly throttle = new TextThrottle();
  private readonly queue: SampleQueue;
  private readonly last: Float64Array;
  private readonly scratch: Float64Array;
  private datagrams = 0;
  private malformed = 0;
  private dropped = 0;
  private repeated = 0;
  private failure = "";
  private listening = false;
  private socket: UdpSocketHandle | undefined;

  constructor(
    private readonly ctx: BlockContext,
    /** undefined: no UDP here (the status says so already). */
    private readonly bridge: UdpBridge | undefined,
    private readonly out: OutputPort,
    private readonly o: HannesReceiverOptions,
  ) {
    const C = o.channels;
    this.where = endpointText(o.host, o.port);
    this.warns = new WarnLimiter(ctx);
    this.queue = new SampleQueue(o.maxDelay, C);
    this.last = new Float64Array(C);
    this.scratch = new Float64Array(C);
    if (bridge) this.describe();
  }

  instance(): BlockInstance {
    return {
      start: () => this.start(),
      process: (f: Frame) => this.process(f),
      stop: () => {
        this.listening = false;
        this.close();
      },
      reset: () => this.reset(),
      dispose: () => this.close(),
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
    try {
      const s = bridge.open({
        bind: { host: this.o.host, port: this.o.port },
        onMessage: (data, from) => this.onMessage(data, from),
        onReady: () => {
          this.listening = true;
          this.describe();
        },
        onError: (message) => this.onError(message),
      });
      if (this.failure === "") this.socket = s;
      else s.close();
    } catch (e) {
      this.onError(e instanceof Error ? e.message : String(e));
    }
  }

  private close(): void {
    const s = this.socket;
    this.socket = undefined;
    s?.close();
  }

  /** One event per tick: the oldest waiting sample, or the last one again. */
  private process(f: Frame): void {
    const n = f.n;
    if (n === 0) return;
    const { out, last, queue } = this;
    const C = this.o.channels;
    const o = out.frame(n);
    for (let e = 0; e < n; e++) {
      o.t[e] = f.t[e]!;
      if (!queue.shift(last)) this.repeated++;
      o.v.set(last, e * C);
    }
    out.emit(o);
    if (this.throttle.due(f.t[n - 1]!)) this.describe();
  }

  private onMessage(data: Uint8Array, from: Endpoint): void {
    this.datagrams++;
    const { channels: C, paced } = this.o;
    if (!decodeHannesEmg(data, C, this.scratch)) {
      this.malformed++;
      this.warns.warn(
        `malformed datagram from ${endpointText(from.host, from.port)} on ${this.where}: ${data.length} bytes, ` +
          `${2 + 2 * C} needed for ${C} channels`,
      );
      this.describe();
      return;
    }
    if (paced) {
      if (!this.queue.push(this.scratch)) this.dropped++;
      return;
    }
    const f = this.out.frame(1);
    f.t[0] = this.ctx.now();
    f.v.set(this.scratch);
    this.last.set(this.scratch);
    this.out.emit(f);
  }

  private onError(message: string): void {
    if (!this.listening) {
      this.failure = `cannot listen on UDP ${this.where}: ${message}`;
      this.close();
    }
    this.warns.warn(this.listening ? `UDP ${this.where}: ${message}` : this.failure);
    this.describe();
  }

  private reset(): void {
    this.queue.clear();
    this.last.fill(0);
    this.datagrams = 0;
    this.malformed = 0;
    this.dropped = 0;
    this.repeated = 0;
    this.warns.reset();
    this.throttle.reset();
    if (this.bridge) this.describe();
  }

  private describe(): void {
    if (this.failure !== "") {
      this.ctx.setText(this.failure);
      return;
    }
    const parts = [
      `${this.listening ? "listening on" : "opening"} ${this.where}`,
      plural(this.datagrams, "datagram"),
    ];
    if (this.dropped > 0) parts.push(`${this.dropped} dropped (MaxDelay)`);
    if (this.repeated > 0) parts.push(`${this.repeated} ticks without a new sample`);
    if (this.malformed > 0) parts.push(`${this.malformed} malformed`);
    this.ctx.setText(parts.join(", "));
  }
}
