/**
 * The connections to OT Bioelettronica's Muovi (docs/protocols.md, "OT Bioelettronica Muovi and
 * SyncStation") over the host's TCP bridge (`ctx.io.tcp`):
 *
 * - `SyncStationLink`: this computer connects to the SyncStation (192.168.76.1:54320), sends the
 *   start command for the enabled probes and parses the stream (muovi-protocol.ts). A refused or
 *   lost connection, or no data for `SILENCE` s, closes it, says why and tries again after 0.5 s,
 *   1 s, 2 s, 4 s, then every 5 s. `close` sends the stop command first.
 * - `MuoviProbeLink`: this computer listens on a port (54321) and a probe connects to it; each
 *   connection gets the start command byte, then the probe streams. A probe that disconnects or
 *   falls silent is reported and the block waits for it to connect again (a new connection
 *   replaces a dead one); a port that cannot be listened on is retried the same way.
 *
 * Both are `StreamLink`s (stream-link.ts): they hand every sample's raw int16 values to `samples`
 * and count what the parser found: samples, samples the device skipped (its counter jumped),
 * malformed data (bytes skipped to realign), connections that ended inside a sample,
 * reconnections.
 */
import type { BlockContext, TcpBridge, TcpServerHandle, TcpSocketHandle } from "../../engine";
import type { DeviceProtocol, DeviceSampleSink } from "./paced-device";
import {
  MUOVI_CHANNELS,
  MUOVI_FULL_SCALE,
  MUOVI_MV_PER_BIT,
  MUOVI_RATE,
  MUOVI_WIRE_CHANNELS,
  MuoviStreamParser,
  probeCommand,
  slotOffsets,
  syncStationChannels,
  syncStationStart,
  syncStationStop,
} from "./muovi-protocol";
import { connectingText, noTcpMessage, StreamLink, type LinkEvents } from "./stream-link";

/** Seconds a listening probe link waits before it warns that no probe connected. */
export const WAIT_WARNING = 5;

export interface SyncStationLinkOptions {
  host: string;
  port: number;
  /** Muovi slots (0…3) in the order the block wants them. */
  slots: readonly number[];
}

/** The SyncStation: this computer is its TCP client (see the file comment). */
export class SyncStationLink extends StreamLink {
  private sock: TcpSocketHandle | undefined;
  private connected = false;

  constructor(
    ctx: BlockContext,
    tcp: TcpBridge,
    private readonly o: SyncStationLinkOptions,
    ev: LinkEvents,
  ) {
    const channels = syncStationChannels(o.slots.length);
    super(ctx, tcp, (onSample) => new MuoviStreamParser(channels, onSample), ev);
  }

  get target(): string {
    const h = this.o.host.includes(":") ? `[${this.o.host}]` : this.o.host;
    return `the SyncStation at ${h}:${this.o.port}`;
  }

  protected hint(): string {
    return "retrying until it answers (join the SyncStation's Wi-Fi; without the device: mosaic run --simulate-devices, or a simulated SyncStation: mosaic simulate syncstation)";
  }

  protected watching(): boolean {
    return this.connected;
  }

  protected streamingText(): string {
    const n = this.o.slots.length;
    return `streaming ${n} Muovi probe${n === 1 ? "" : "s"} (${n * 32} EMG channels) at ${MUOVI_RATE} Hz from ${this.target}`;
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
          this.sock?.write(syncStationStart(this.o.slots));
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
    if (this.sock && this.connected && stop) this.sock.write(syncStationStop());
    this.sock?.close();
    this.sock = undefined;
    this.connected = false;
  }
}

export interface MuoviProbeLinkOptions {
  /** Local address to listen on ("0.0.0.0": every interface). */
  host: string;
  port: number;
}

/** A single probe: this computer listens and the probe connects (see the file comment). */
export class MuoviProbeLink extends StreamLink {
  private server: TcpServerHandle | undefined;
  private peer: TcpSocketHandle | undefined;
  private peerName = "";
  private listeningPort = 0;

  constructor(
    ctx: BlockContext,
    tcp: TcpBridge,
    private readonly o: MuoviProbeLinkOptions,
    ev: LinkEvents,
  ) {
    super(ctx, tcp, (onSample) => new MuoviStreamParser(MUOVI_WIRE_CHANNELS, onSample), ev);
  }

  get target(): string {
    return this.peerName
      ? `the Muovi probe at ${this.peerName}`
      : `a Muovi probe on TCP port ${this.listeningPort || this.o.port}`;
  }

  /** The port listened on (the one chosen when Port was 0), 0 before listening. */
  get port(): number {
    return this.listeningPort;
  }

  protected hint(): string {
    return "waiting (join the probe's Wi-Fi, hold its button 5 s; without the device: mosaic run --simulate-devices, or a simulated probe: mosaic simulate muovi --connect HOST:PORT)";
  }

  protected watching(): boolean {
    return this.peer !== undefined;
  }

  protected streamingText(): string {
    return `streaming 32 EMG channels at ${MUOVI_RATE} Hz from ${this.target}`;
  }

  protected attempt(): void {
    const gen = ++this.gen;
    if (this.server) {
      // Still listening: wait for the probe.
      this.waiting();
      return;
    }
    this.server = this.tcp.listen!(
      { host: this.o.host, port: this.o.port },
      {
        onListening: (local) => {
          this.listeningPort = local.port;
          if (this.listeningSince < 0) this.listeningSince = this.ctx.now();
          if (gen !== this.gen) return;
          this.waiting();
        },
        onPeer: (remote, peer) => this.onPeer(remote, peer),
        onError: (reason) => {
          this.server = undefined;
          this.fail(this.gen, reason);
        },
      },
    );
  }

  private listeningSince = -1;
  private saidWaiting = false;

  /** Said once: no probe has connected for WAIT_WARNING s after listening began. */
  protected override idle(now: number): void {
    if (this.saidWaiting || this.everStreamed || this.peer || this.listeningSince < 0) return;
    if (now - this.listeningSince < WAIT_WARNING) return;
    this.saidWaiting = true;
    this.ev.warn(
      `no Muovi probe has connected to port ${this.listeningPort || this.o.port} in ${WAIT_WARNING} s; ${this.hint()}`,
    );
  }

  protected override retryText(wait: number): string {
    return this.server
      ? `waiting for it to connect again to port ${this.listeningPort || this.o.port}`
      : `listening again in ${wait} s (attempt ${this.counts.failures + 1})`;
  }

  private waiting(): void {
    this.ev.state(
      "connecting",
      `waiting for a Muovi probe to connect to port ${this.listeningPort || this.o.port}…`,
    );
  }

  private onPeer(remote: { host: string; port: number }, peer: TcpSocketHandle) {
    // A new connection replaces the current one (a probe that came back before the old
    // connection timed out). The Node bridge ends the old one first (reported through its
    // onClose); should a bridge not, the old socket is closed here and what it left is dropped.
    const gen = ++this.gen;
    const old = this.peer;
    this.peer = undefined;
    old?.close();
    this.endStream();
    this.peer = peer;
    this.peerName = remote.host.includes(":")
      ? `[${remote.host}]:${remote.port}`
      : `${remote.host}:${remote.port}`;
    this.lastData = this.ctx.now();
    this.retryAt = -1;
    peer.write(Uint8Array.of(probeCommand(true)));
    this.ev.state("connecting", `${this.target} connected; started it, waiting for its samples…`);
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
    if (this.peer && stop) this.peer.write(Uint8Array.of(probeCommand(false)));
    this.peer?.close();
    this.peer = undefined;
    if (this.closed) {
      this.server?.close();
      this.server = undefined;
    }
  }
}

/**
 * The SyncStation as the timer-paced Muovi block's protocol module: every `averageOver` raw
 * samples become one sample of 32 EMG channels per probe (in the order of `Probes`), each the
 * mean of raw / 32768 as the original computed it.
 */
export function muoviProtocol(
  link: { Probes: readonly number[]; Host: string; Port: number },
  averageOver: number,
  onLink?: (l: SyncStationLink) => void,
): DeviceProtocol {
  return {
    open(ctx: BlockContext, sink: DeviceSampleSink) {
      const o = { host: link.Host, port: link.Port, slots: link.Probes };
      const tcp = ctx.io.tcp;
      if (!tcp) {
        const target = `the SyncStation at ${o.host}:${o.port}`;
        sink.state("lost", "TCP not available in the browser build; use --simulate-devices");
        sink.warn(noTcpMessage(target));
        return undefined;
      }
      const offsets = slotOffsets(link.Probes);
      const acc = new Float64Array(MUOVI_CHANNELS * offsets.length);
      let n = 0;
      const l = new SyncStationLink(ctx, tcp, o, {
        samples(raw) {
          for (let i = 0; i < offsets.length; i++) {
            const off = offsets[i]!;
            for (let j = 0; j < MUOVI_CHANNELS; j++) {
              acc[i * MUOVI_CHANNELS + j]! += raw[off + j]! / MUOVI_FULL_SCALE / averageOver;
            }
          }
          if (++n < averageOver) return;
          sink.push(acc);
          acc.fill(0);
          n = 0;
        },
        state(phase, text) {
          if (phase !== "streaming") {
            acc.fill(0);
            n = 0;
          }
          sink.state(phase, text);
        },
        warn: (m) => sink.warn(m),
      });
      onLink?.(l);
      l.open();
      return { close: () => l.close() };
    },
  };
}

/**
 * A single probe as MuoviSingleProbe's protocol module: every `rows` raw samples become one
 * [rows, 32 × probes] matrix in mV (raw × 0.000286); the probe fills the first 32 columns.
 */
export function muoviProbeProtocol(
  link: { Probes: readonly number[]; Port: number; Host?: string },
  rows: number,
  onLink?: (l: MuoviProbeLink) => void,
): DeviceProtocol {
  return {
    open(ctx: BlockContext, sink: DeviceSampleSink) {
      const o = { host: link.Host ?? "0.0.0.0", port: link.Port };
      const tcp = ctx.io.tcp;
      if (!tcp?.listen) {
        const target = `a Muovi probe on TCP port ${o.port}`;
        sink.state("lost", "TCP not available in the browser build; use --simulate-devices");
        sink.warn(noTcpMessage(target));
        return undefined;
      }
      const cols = MUOVI_CHANNELS * link.Probes.length;
      const m = new Float64Array(rows * cols);
      let r = 0;
      const l = new MuoviProbeLink(ctx, tcp, o, {
        samples(raw) {
          for (let j = 0; j < MUOVI_CHANNELS; j++) m[r * cols + j] = raw[j]! * MUOVI_MV_PER_BIT;
          if (++r < rows) return;
          sink.push(m);
          r = 0;
        },
        state(phase, text) {
          if (phase !== "streaming") r = 0;
          sink.state(phase, text);
        },
        warn: (msg) => sink.warn(msg),
      });
      onLink?.(l);
      l.open();
      return { close: () => l.close() };
    },
  };
}
