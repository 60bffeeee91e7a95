/**
 * One UdpSender at run time: opens the socket, encodes every input event into datagrams, counts
 * what was sent and what was not, and shows it in the status (the behaviour is described in the
 * block's help, udp-sender.ts).
 */
import type { BlockContext, BlockInstance, Frame, UdpBridge, UdpSocketHandle } from "../../engine";
import { formatCount, plural, TextThrottle } from "../shared/text";
import type { RawEncoder, StreamlinedEncoder, ValueType } from "./udp-format";
import type { Serializer } from "./udp-sender";
import { WarnLimiter, NO_UDP } from "./udp-common";

/** How one input is sent. */
export interface Plan {
  serializer: Serializer;
  type: ValueType;
  category: number;
  subcategories: number[];
  scale: number;
}

/** One input's encoder. */
export interface Lane {
  plan: Plan;
  size: number;
  perValue: boolean;
  sEnc: StreamlinedEncoder | undefined;
  rEnc: RawEncoder | undefined;
}

/** What the block's params and inputs decide before the run starts. */
export interface UdpSenderSettings {
  host: string;
  port: number;
  /** `[::1]:5000`, `127.0.0.1:5000`. */
  dest: string;
  /** The serializers in use, as the status names them. */
  what: string;
  /** Timestamp "send": the clock time at sending instead of the event's. */
  sendTime: boolean;
  lanes: Lane[];
}

export class UdpSenderRun {
  private socket: UdpSocketHandle | undefined;
  /** MOSAIC's one counter over every datagram the block sends. */
  private counter = 0;
  /** Datagrams handed to the socket, and of those (or of datagrams that had no socket) not sent. */
  private handed = 0;
  private failed = 0;
  /** Events not sent because UDP is unavailable here. */
  private notSent = 0;
  private lastError = "";
  private readonly unavailable: boolean;
  private describeQueued = false;
  private readonly warns: WarnLimiter;
  private readonly throttle = new TextThrottle();

  /** `bridge` undefined: UDP is unavailable here (udpBridge has said so in the status). */
  constructor(
    private readonly ctx: BlockContext,
    private readonly s: UdpSenderSettings,
    private readonly bridge: UdpBridge | undefined,
  ) {
    this.warns = new WarnLimiter(ctx);
    this.unavailable = bridge === undefined;
    if (bridge) this.describe();
  }

  instance(): BlockInstance {
    return {
      start: () => this.start(),
      process: (f, port) => this.process(f, port),
      stop: () => {
        this.close();
        this.describe();
      },
      reset: () => this.reset(),
      dispose: () => this.close(),
    };
  }

  private start(): void {
    if (!this.bridge) {
      this.ctx.warn(`${NO_UDP}: this block sends nothing`);
      return;
    }
    if (this.socket) return;
    try {
      this.socket = this.bridge.open({
        remote: { host: this.s.host, port: this.s.port },
        onError: this.onError,
      });
    } catch (e) {
      this.onError(e instanceof Error ? e.message : String(e));
    }
  }

  private process(f: Frame, port: number): void {
    const s = this.socket;
    if (s) this.send(s, f, this.s.lanes[port]!);
    else this.countUnsent(f, port);
    const n = f.n;
    if (n > 0 && this.throttle.due(f.t[n - 1]!)) this.describe();
  }

  /** Encodes the events of `f` with `lane` and hands every datagram to the socket. */
  private send(s: UdpSocketHandle, f: Frame, lane: Lane): void {
    const { rEnc, sEnc, size } = lane;
    const { category, subcategories: subs, scale } = lane.plan;
    const sendTime = this.s.sendTime;
    if (sEnc) sEnc.counter = this.counter;
    const n = f.n;
    const v = f.v;
    const stride = f.stride;
    for (let e = 0; e < n; e++) {
      const off = e * stride;
      if (rEnc) {
        s.send(rEnc.encode(v, off, scale));
        this.handed++;
      } else if (lane.perValue) {
        const t = sendTime ? this.ctx.now() : f.t[e]!;
        for (let k = 0; k < size; k++) {
          s.send(sEnc!.encode(t, category, subs[k]!, v, off + k, scale));
          this.handed++;
        }
      } else {
        const t = sendTime ? this.ctx.now() : f.t[e]!;
        s.send(sEnc!.encode(t, category, subs[0]!, v, off, scale));
        this.handed++;
      }
    }
    if (sEnc) this.counter = sEnc.counter;
  }

  /** No socket: UDP unavailable, before start, or a socket that could not be opened. */
  private countUnsent(f: Frame, port: number): void {
    const n = f.n;
    if (this.unavailable) this.notSent += n;
    else if (n > 0) {
      // Before start or after a socket that could not be opened: counted as not sent.
      const d = n * this.perEvent(port);
      this.handed += d;
      this.failed += d;
      this.lastError ||= "no socket";
    }
  }

  /** Datagrams one event of input `port` makes. */
  private perEvent(port: number): number {
    const l = this.s.lanes[port]!;
    return l.perValue ? l.size : 1;
  }

  // The bridge calls onError once per datagram it did not send (native-bridges/udp.ts), often
  // many at once (a queue dropped when a name does not resolve): the text is rebuilt once after
  // each burst, warnings are rate-limited and say how many datagrams are lost in all.
  private readonly onError = (message: string): void => {
    this.failed++;
    this.lastError = message;
    this.warns.warn(
      `UDP to ${this.s.dest}: ${message} (${plural(this.failed, "datagram")} not sent so far)`,
    );
    this.describeSoon();
  };

  private describeSoon(): void {
    if (this.describeQueued) return;
    this.describeQueued = true;
    queueMicrotask(() => {
      this.describeQueued = false;
      this.describe();
    });
  }

  private describe(): void {
    if (this.unavailable) {
      this.ctx.setText(`${NO_UDP}: ${plural(this.notSent, "event")} not sent`);
      return;
    }
    const err = this.failed > 0 ? `, ${formatCount(this.failed)} not sent (${this.lastError})` : "";
    const sent = plural(Math.max(0, this.handed - this.failed), "datagram");
    this.ctx.setText(`→ ${this.s.dest} (${this.s.what}): ${sent} sent${err}`);
  }

  private reset(): void {
    this.counter = 0;
    this.handed = 0;
    this.failed = 0;
    this.notSent = 0;
    this.lastError = "";
    this.throttle.reset();
    this.warns.reset();
    this.describe();
  }

  private close(): void {
    const s = this.socket;
    this.socket = undefined;
    s?.close();
  }
}
