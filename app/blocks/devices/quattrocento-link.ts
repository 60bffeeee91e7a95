/**
 * The connection to OT Bioelettronica's Quattrocento (docs/protocols.md, "OT Bioelettronica
 * Quattrocento") over the host's TCP bridge (`ctx.io.tcp`): this computer connects to the
 * device (169.254.1.10:23456), sends the 40-byte configuration command with acquisition on and
 * parses the stream (quattrocento-protocol.ts). A `StreamLink` (stream-link.ts): a refused or
 * lost connection, or no data for `SILENCE` s, closes it, says why and tries again after 0.5 s,
 * 1 s, 2 s, 4 s, then every 5 s; `close` sends the command with acquisition off first. Every
 * sample's raw int16 values go to `samples`; the counts (samples, samples the device skipped,
 * malformed data, truncated samples, reconnections) are the parser's and the link's.
 */
import type { BlockContext, TcpBridge, TcpSocketHandle } from "../../engine";
import {
  QUATTROCENTO_CHANNEL_COUNTS,
  quattrocentoCommand,
  QuattrocentoStreamParser,
  type QuattrocentoConfig,
} from "./quattrocento-protocol";
import { connectingText, StreamLink, type LinkEvents } from "./stream-link";

export interface QuattrocentoLinkOptions {
  host: string;
  port: number;
  config: QuattrocentoConfig;
  /** Output channels, for the status line. */
  outputs: number;
}

/** "the Quattrocento at host:port" (IPv6 in brackets). */
export function quattrocentoTarget(host: string, port: number): string {
  return `the Quattrocento at ${host.includes(":") ? `[${host}]` : host}:${port}`;
}

/** The Quattrocento: this computer is its TCP client (see the file comment). */
export class QuattrocentoLink extends StreamLink {
  private sock: TcpSocketHandle | undefined;
  private connected = false;
  private readonly channels: number;

  constructor(
    ctx: BlockContext,
    tcp: TcpBridge,
    private readonly o: QuattrocentoLinkOptions,
    ev: LinkEvents,
  ) {
    const channels = QUATTROCENTO_CHANNEL_COUNTS[o.config.nch]!;
    super(ctx, tcp, (onSample) => new QuattrocentoStreamParser(channels, onSample), ev);
    this.channels = channels;
  }

  get target(): string {
    return quattrocentoTarget(this.o.host, this.o.port);
  }

  protected hint(): string {
    return "retrying until it answers (connect this computer to the Quattrocento's Ethernet port, e.g. a link-local 169.254.x.x address; without the device: mosaic run --simulate-devices, or a simulated Quattrocento: mosaic simulate quattrocento)";
  }

  protected watching(): boolean {
    return this.connected;
  }

  protected streamingText(): string {
    return `streaming ${this.o.outputs} of ${this.channels} channels at ${this.o.config.rate} Hz from ${this.target}`;
  }

  protected attempt(): void {
    const gen = ++this.gen;
    this.ev.state("connecting", connectingText(this.target, this.counts.failures));
    this.sock = this.tcp.connect(
      { host: this.o.host, port: this.o.port },
      {
        onConnect: () => {
          if (gen !== this.gen) return;
          this.connected = true;
          this.lastData = this.ctx.now();
          this.sock?.write(quattrocentoCommand(this.o.config, true));
          this.ev.state("connecting", `configured ${this.target}; waiting for its samples…`);
        },
        onData: (d) => this.onData(gen, d),
        onClose: (reason, wasOpen) =>
          this.fail(gen, wasOpen ? `the connection ended: ${reason}` : reason),
      },
      { timeoutMs: 3000 },
    );
  }

  protected drop(stop: boolean): void {
    if (this.sock && this.connected && stop) {
      this.sock.write(quattrocentoCommand(this.o.config, false));
    }
    this.sock?.close();
    this.sock = undefined;
    this.connected = false;
  }
}
