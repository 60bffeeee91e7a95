/**
 * What the UDP output blocks that drive a device's program (BlenderArm, HannesGUI) share at run
 * time: one socket to the destination, opened at start (or a warning when there is no UDP here),
 * closed at stop and dispose; failed sends counted, warned about (rate-limited) and shown; the
 * counts zeroed at reset. A subclass encodes and sends its events and words its status.
 */
import type { BlockContext, BlockInstance, Frame, UdpBridge, UdpSocketHandle } from "../../engine";
import { TextThrottle } from "../shared/text";
import { endpointText, NO_UDP, udpBridge, WarnLimiter } from "./udp-common";

export abstract class UdpOutputRun {
  protected socket: UdpSocketHandle | undefined;
  /** Sends and opens that failed, and the last one's message. */
  protected failed = 0;
  protected lastError = "";
  /** Events not sent because no socket was open. */
  protected notSent = 0;
  /** `[::1]:5000`, `127.0.0.1:5000`. */
  protected readonly dest: string;
  protected readonly throttle = new TextThrottle();
  private readonly warns: WarnLimiter;
  /** Undefined: UDP is unavailable here (udpBridge has said so in the status). */
  protected readonly bridge: UdpBridge | undefined;

  /** `receiver`: who gets nothing without UDP, for the warning ("the Blender arm"). */
  constructor(
    protected readonly ctx: BlockContext,
    private readonly host: string,
    private readonly port: number,
    private readonly receiver: string,
  ) {
    this.dest = endpointText(host, port);
    this.warns = new WarnLimiter(ctx);
    this.bridge = udpBridge(ctx);
  }

  /** Sends the events of input `port` (counting them as not sent without a socket). */
  protected abstract process(f: Frame, port: number): void;
  /** Shows the status. */
  protected abstract describe(): void;
  /** Zeroes the subclass's own counts (reset does the shared ones). */
  protected abstract clearCounts(): void;

  /** The block instance the engine drives. */
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

  /** Opens the socket (once), or warns that without UDP the receiver gets nothing. */
  private start(): void {
    if (!this.bridge) {
      this.ctx.warn(`${NO_UDP}: ${this.receiver} gets nothing`);
      return;
    }
    if (this.socket) return;
    try {
      this.socket = this.bridge.open({
        remote: { host: this.host, port: this.port },
        onError: this.onError,
      });
    } catch (e) {
      this.onError(e instanceof Error ? e.message : String(e));
    }
  }

  /** Counts a failed send or open, warns (rate-limited) and shows it. */
  protected readonly onError = (message: string): void => {
    this.failed++;
    this.lastError = message;
    this.warns.warn(`UDP to ${this.dest}: ${message}`);
    this.describe();
  };

  /** Zeroes the counts, the status throttle and the warning limiter, and shows the status. */
  private reset(): void {
    this.clearCounts();
    this.failed = 0;
    this.notSent = 0;
    this.lastError = "";
    this.throttle.reset();
    this.warns.reset();
    this.describe();
  }

  /** Closes the socket, if open (a send error arriving meanwhile finds none). */
  private close(): void {
    const s = this.socket;
    this.socket = undefined;
    s?.close();
  }
}
