/**
 * The connection to an OT Bioelettronica Sessantaquattro or Sessantaquattro+ (docs/protocols.md,
 * "OT Bioelettronica Sessantaquattro") over the host's TCP bridge (`ctx.io.tcp`): this computer
 * listens on a port (45454) and the device connects to it; each connection gets the command word
 * with GO set (the configuration: mode, channels, rate, resolution, high-pass), then the device
 * streams. A device that disconnects or falls silent for `SILENCE` s is reported and the link
 * waits for it to connect again (a new connection replaces a dead one); a port that cannot be
 * listened on (taken, not this computer's address) is said and tried again after 0.5 s, 1 s, 2 s,
 * 4 s, then every 5 s. `close` sends the command word with GO clear first (the device stops and
 * closes its socket).
 *
 * A `StreamLink` (stream-link.ts): every sample's raw values go to `samples`, and the counts say
 * what the parser found: samples, samples the device skipped (its counter jumped), malformed data
 * (bytes skipped to realign), connections that ended inside a sample, reconnections.
 */
import type { BlockContext, TcpBridge, TcpServerHandle, TcpSocketHandle } from "../../engine";
import {
  commandWord,
  encodeCommand,
  SessantaquattroStreamParser,
  wireLayout,
  type SessantaquattroConfig,
} from "./sessantaquattro-protocol";
import { StreamLink, type LinkEvents } from "./stream-link";

/** Seconds a listening link waits before it warns that no device connected. */
export const WAIT_WARNING = 5;

export interface SessantaquattroLinkOptions {
  /** Local address to listen on ("0.0.0.0": every interface). */
  host: string;
  port: number;
  config: SessantaquattroConfig;
}

/** "a Sessantaquattro+ on TCP port 45454" (before it connected). */
export function sessantaquattroTarget(model: string, port: number): string {
  return `a ${model} on TCP port ${port}`;
}

const peerText = (r: { host: string; port: number }): string =>
  r.host.includes(":") ? `[${r.host}]:${r.port}` : `${r.host}:${r.port}`;

/** The device connects to this computer (see the file comment). */
export class SessantaquattroLink extends StreamLink<Int32Array> {
  private server: TcpServerHandle | undefined;
  private peer: TcpSocketHandle | undefined;
  private peerName = "";
  private listeningPort = 0;
  private listeningSince = -1;
  private saidWaiting = false;
  private readonly channels: number;

  constructor(
    ctx: BlockContext,
    tcp: TcpBridge,
    private readonly o: SessantaquattroLinkOptions,
    ev: LinkEvents<Int32Array>,
  ) {
    const channels = wireLayout(o.config).length;
    const bytes = o.config.highRes ? 3 : 2;
    super(ctx, tcp, (onSample) => new SessantaquattroStreamParser(channels, bytes, onSample), ev);
    this.channels = channels;
  }

  private get portShown(): number {
    return this.listeningPort || this.o.port;
  }

  get target(): string {
    const m = this.o.config.model;
    return this.peerName
      ? `the ${m} at ${this.peerName}`
      : sessantaquattroTarget(m, this.portShown);
  }

  /** The port listened on (the one chosen when Port was 0), 0 before listening. */
  get port(): number {
    return this.listeningPort;
  }

  protected hint(): string {
    return `the device connects to this computer's port ${this.portShown} (join its Wi-Fi, or set its "Server IP address" on its web page; without the device: mosaic run --simulate-devices, or a simulated one: mosaic simulate sessantaquattro --connect HOST:PORT)`;
  }

  protected watching(): boolean {
    return this.peer !== undefined;
  }

  protected streamingText(): string {
    const c = this.o.config;
    const bits = c.highRes ? 24 : 16;
    return `streaming ${this.channels} channels (${c.mode}, ${bits}-bit) at ${c.rate} Hz from ${this.target}`;
  }

  protected attempt(): void {
    const gen = ++this.gen;
    if (this.server) {
      this.waiting();
      return;
    }
    this.server = this.tcp.listen!(
      { host: this.o.host, port: this.o.port },
      {
        onListening: (local) => {
          this.listeningPort = local.port;
          if (this.listeningSince < 0) this.listeningSince = this.ctx.now();
          if (gen === this.gen) this.waiting();
        },
        onPeer: (remote, peer) => this.onPeer(remote, peer),
        onError: (reason) => {
          this.server = undefined;
          this.fail(this.gen, reason);
        },
      },
    );
  }

  /** Said once: no device has connected for WAIT_WARNING s after listening began. */
  protected override idle(now: number): void {
    if (this.saidWaiting || this.everStreamed || this.peer || this.listeningSince < 0) return;
    if (now - this.listeningSince < WAIT_WARNING) return;
    this.saidWaiting = true;
    this.ev.warn(
      `no ${this.o.config.model} has connected to port ${this.portShown} in ${WAIT_WARNING} s; ${this.hint()}`,
    );
  }

  protected override retryText(wait: number): string {
    return this.server
      ? `waiting for it to connect again to port ${this.portShown}`
      : `listening again in ${wait} s (attempt ${this.counts.failures + 1})`;
  }

  private waiting(): void {
    this.ev.state(
      "connecting",
      `waiting for a ${this.o.config.model} to connect to port ${this.portShown}…`,
    );
  }

  private onPeer(remote: { host: string; port: number }, peer: TcpSocketHandle) {
    // A new connection replaces an older one (a device that reconnected before its old
    // connection timed out): the old one is closed and what its stream left is dropped.
    const gen = ++this.gen;
    if (this.peer) {
      this.peer.close();
      this.endStream();
    }
    this.peer = peer;
    this.peerName = peerText(remote);
    this.lastData = this.ctx.now();
    this.retryAt = -1;
    const word = commandWord(this.o.config, true);
    peer.write(encodeCommand(word));
    this.ev.state(
      "connecting",
      `${this.target} connected; sent command 0x${word.toString(16).padStart(4, "0")}, waiting for its samples…`,
    );
    return {
      onData: (d: Uint8Array) => this.onData(gen, d),
      onClose: (reason: string) => {
        if (gen !== this.gen) return;
        this.peer = undefined;
        this.fail(gen, `the connection ended: ${reason}`);
        this.peerName = "";
      },
    };
  }

  protected drop(stop: boolean): void {
    if (this.peer && stop) this.peer.write(encodeCommand(commandWord(this.o.config, false)));
    this.peer?.close();
    this.peer = undefined;
    if (this.closed) {
      this.server?.close();
      this.server = undefined;
    }
  }
}
