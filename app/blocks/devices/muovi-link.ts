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
 * Both hand every sample's raw int16 values to `samples` and count what the parser found: samples,
 * samples the device skipped (its counter jumped), malformed data (bytes skipped to realign),
 * connections that ended inside a sample, reconnections.
 */
import {
  vectorShape,
  type BlockContext,
  type BlockInstance,
  type TcpBridge,
  type TcpServerHandle,
  type TcpSocketHandle,
} from "../../engine";
import { plural, TextThrottle } from "../shared/text";
import { DeviceClock } from "./delsys-protocol";
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

/** Seconds without data after which a connection counts as lost. */
export const SILENCE = 2;
/** Waits between attempts, s: doubling from the first up to the last. */
export const RETRY_FIRST = 0.5;
export const RETRY_MAX = 5;
/** Seconds a listening probe link waits before it warns that no probe connected. */
export const WAIT_WARNING = 5;
/** How often the link looks at its deadlines, s. */
const HEARTBEAT = 0.1;

export type MuoviPhase = "connecting" | "streaming" | "lost";

export interface MuoviLinkEvents {
  /** One sample's raw values (all channels on the wire; valid during the call). */
  samples(raw: Int16Array): void;
  state(phase: MuoviPhase, text: string): void;
  warn(message: string): void;
  /** The samples of one TCP chunk have all been given (the native form emits them as a frame). */
  chunkEnd?(): void;
}

export interface MuoviCounts {
  samples: number;
  /** Samples the device skipped (its counter jumped ahead). */
  lostSamples: number;
  /** Times the counter restarted (or jumped too far to count the samples in between). */
  counterJumps: number;
  malformed: number;
  skippedBytes: number;
  lastProblem: string;
  /** Connections that ended inside a sample, and the bytes lost that way. */
  truncated: number;
  truncatedBytes: number;
  reconnections: number;
  failures: number;
}

/** What both links share: the parser, the counts, the heartbeat, retries. */
abstract class MuoviLinkBase {
  protected gen = 0;
  protected closed = true;
  protected streaming = false;
  protected everStreamed = false;
  protected lastData = 0;
  protected retryAt = -1;
  protected readonly parser: MuoviStreamParser;
  readonly counts: MuoviCounts = {
    samples: 0,
    lostSamples: 0,
    counterJumps: 0,
    malformed: 0,
    skippedBytes: 0,
    lastProblem: "",
    truncated: 0,
    truncatedBytes: 0,
    reconnections: 0,
    failures: 0,
  };

  constructor(
    protected readonly ctx: BlockContext,
    protected readonly tcp: TcpBridge,
    channels: number,
    protected readonly ev: MuoviLinkEvents,
  ) {
    this.parser = new MuoviStreamParser(channels, (raw) => ev.samples(raw));
  }

  /** "the SyncStation at 192.168.76.1:54320". */
  abstract get target(): string;
  protected abstract attempt(): void;
  /** Closes the transport (the stop command first when `stop`). */
  protected abstract drop(stop: boolean): void;

  open(): void {
    if (!this.closed) return;
    this.closed = false;
    this.counts.failures = 0;
    this.attempt();
    this.heartbeat();
  }

  close(): void {
    if (this.closed) return;
    this.closed = true;
    this.gen++;
    this.drop(true);
    this.endStream();
  }

  private heartbeat(): void {
    if (this.closed) return;
    const now = this.ctx.now();
    if (this.retryAt >= 0 && now >= this.retryAt) {
      this.retryAt = -1;
      this.attempt();
    } else if (this.watching() && now - this.lastData > SILENCE) {
      this.fail(this.gen, `no data for ${SILENCE} s`);
    } else this.idle(now);
    this.ctx.at(this.ctx.now() + HEARTBEAT, () => this.heartbeat());
  }

  /** Called on heartbeats with nothing else to do. */
  protected idle(_now: number): void {}

  /** Whether silence counts now (a connection is up and configured). */
  protected abstract watching(): boolean;

  protected onData(gen: number, chunk: Uint8Array): void {
    if (gen !== this.gen || this.closed) return;
    this.lastData = this.ctx.now();
    const p = this.parser;
    const before = p.malformed;
    p.feed(chunk);
    const c = this.counts;
    c.samples = p.samples;
    c.lostSamples = p.lostSamples;
    c.counterJumps = p.counterJumps;
    c.malformed = p.malformed;
    c.skippedBytes = p.skippedBytes;
    c.lastProblem = p.lastProblem;
    if (p.malformed > before) {
      this.ev.warn(
        `malformed data from ${this.target} (${p.lastProblem}): skipping to the next whole sample (${p.malformed} so far)`,
      );
    }
    if (!this.streaming && p.samples > 0) this.began();
    else if (this.streaming && this.extras() !== this.shownExtras) {
      this.ev.state("streaming", this.statusText());
    }
    this.ev.chunkEnd?.();
  }

  private shownExtras = "";

  /** The counts worth seeing in the status line: " · 3 skipped by the device · …". */
  private extras(): string {
    const c = this.counts;
    let t = "";
    if (c.lostSamples > 0) t += ` · ${c.lostSamples} samples skipped by the device`;
    if (c.malformed > 0) t += ` · ${c.malformed} malformed (${c.skippedBytes} bytes skipped)`;
    if (c.truncated > 0) t += ` · ${c.truncated} truncated`;
    if (c.reconnections > 0) t += ` · reconnected ${c.reconnections}×`;
    return t;
  }

  private statusText(): string {
    this.shownExtras = this.extras();
    return this.streamingText() + this.shownExtras;
  }

  private began(): void {
    this.streaming = true;
    const reconnected = this.everStreamed;
    if (reconnected) this.counts.reconnections++;
    this.everStreamed = true;
    const attempts = this.counts.failures;
    this.counts.failures = 0;
    this.ev.state("streaming", this.statusText());
    if (reconnected) {
      this.ev.warn(
        `reconnected to ${this.target} after ${attempts} failed attempt${attempts === 1 ? "" : "s"}; streaming again`,
      );
    }
  }

  protected abstract streamingText(): string;

  /** The stream ended: what the parser held is a truncated sample. */
  protected endStream(): void {
    const wasStreaming = this.streaming;
    this.streaming = false;
    const held = this.parser.reset();
    if (held > 0 && wasStreaming) {
      this.counts.truncated++;
      this.counts.truncatedBytes += held;
      if (!this.closed) {
        this.ev.warn(
          `the stream from ${this.target} ended inside a sample (${held} of ${this.parser.sampleBytes} bytes): dropped`,
        );
      }
    }
  }

  /** Something failed: close, say why, try again later. */
  protected fail(gen: number, reason: string): void {
    if (gen !== this.gen || this.closed) return;
    const wasStreaming = this.streaming;
    this.gen++;
    this.drop(false);
    this.endStream();
    this.counts.failures++;
    const wait = Math.min(RETRY_MAX, RETRY_FIRST * 2 ** (this.counts.failures - 1));
    const head = this.everStreamed
      ? wasStreaming
        ? `lost ${this.target}: ${reason}`
        : `still lost: ${reason}`
      : `not reachable: ${reason}`;
    this.ev.state("lost", `${head}; ${this.retryText(wait)}`);
    if (wasStreaming) this.ev.warn(`lost ${this.target}: ${reason}; reconnecting`);
    else if (this.counts.failures === 1 && !this.everStreamed) {
      this.ev.warn(`${this.target} ${head}; ${this.hint()}`);
    }
    this.retryAt = this.ctx.now() + wait;
  }

  protected abstract hint(): string;

  /** What happens next, for the status: "retrying in 1 s (attempt 3)". */
  protected retryText(wait: number): string {
    return `retrying in ${wait} s (attempt ${this.counts.failures + 1})`;
  }
}

export interface SyncStationLinkOptions {
  host: string;
  port: number;
  /** Muovi slots (0…3) in the order the block wants them. */
  slots: readonly number[];
}

/** The SyncStation: this computer is its TCP client (see the file comment). */
export class SyncStationLink extends MuoviLinkBase {
  private sock: TcpSocketHandle | undefined;
  private connected = false;

  constructor(
    ctx: BlockContext,
    tcp: TcpBridge,
    private readonly o: SyncStationLinkOptions,
    ev: MuoviLinkEvents,
  ) {
    super(ctx, tcp, syncStationChannels(o.slots.length), ev);
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
    this.ev.state(
      "connecting",
      this.counts.failures > 0
        ? `connecting to ${this.target} (attempt ${this.counts.failures + 1})…`
        : `connecting to ${this.target}…`,
    );
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
export class MuoviProbeLink extends MuoviLinkBase {
  private server: TcpServerHandle | undefined;
  private peer: TcpSocketHandle | undefined;
  private peerName = "";
  private listeningPort = 0;

  constructor(
    ctx: BlockContext,
    tcp: TcpBridge,
    private readonly o: MuoviProbeLinkOptions,
    ev: MuoviLinkEvents,
  ) {
    super(ctx, tcp, MUOVI_WIRE_CHANNELS, ev);
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
    // A new connection: the old one (if any) has ended; this one is current.
    const gen = ++this.gen;
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

/** The sentence for a host without TCP (the browser build). */
export function noTcpMessage(target: string): string {
  return `TCP not available in the browser build; use --simulate-devices (or the app's Simulate devices switch): ${target} cannot be reached and this block sends zeros`;
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

/** One line of counts, for the blocks' `counts` action. */
export function muoviCountsText(c: MuoviCounts | undefined): string {
  if (!c) return "not started";
  return (
    `${c.samples} samples, ${c.lostSamples} skipped by the device, ${c.counterJumps} counter restarts, ${c.reconnections} reconnections, ` +
    `${c.malformed} malformed (${c.skippedBytes} bytes skipped${c.lastProblem ? `, last: ${c.lastProblem}` : ""}), ` +
    `${c.truncated} truncated (${c.truncatedBytes} bytes)`
  );
}

export interface NativeMuoviOptions {
  /** Output channels (vector [1, channels] per sample). */
  channels: number;
  /** "the SyncStation at …", for the no-TCP message. */
  target: string;
  /** Whether this host can reach the device (a TCP bridge, with listen when needed). */
  available(ctx: BlockContext): boolean;
  /** Opens the link with these events (the bridge is available). */
  open(ctx: BlockContext, ev: MuoviLinkEvents): { close(): void };
  /** Writes one sample's output values from its raw values at `out[at…]`. */
  convert(raw: Int16Array, out: Float64Array, at: number): void;
}

/**
 * The blocks without an input: their own source at the device's 2000 Hz. The samples of each TCP
 * chunk go out at once as one frame, stamped on the device's sample clock (the first batch's last
 * sample at its arrival, then 1 / 2000 s apart, at most one SyncStation packet, 20 ms, ahead of
 * arrival; re-anchored after a loss, the gap counted).
 */
export function nativeMuoviSource(ctx: BlockContext, o: NativeMuoviOptions): BlockInstance {
  if (ctx.declaredRate === undefined) ctx.setDesiredRate(MUOVI_RATE);
  const k = o.channels;
  const out = ctx.output(vectorShape(k), "emg");
  const clock = new DeviceClock(MUOVI_RATE, 0.5, 40 / MUOVI_RATE);
  const throttle = new TextThrottle(0.5);
  let batch = new Float64Array(64 * k);
  let n = 0;
  let emitted = 0;
  let phase = "stopped";
  let lastText = "";
  let link: { close(): void } | undefined;

  const refresh = (): void => {
    let text = phase;
    if (emitted > 0) text += ` · ${plural(emitted, "sample")}`;
    if (clock.gapSamples > 0) text += ` · ${clock.gapSamples} samples lost in gaps`;
    if (text !== lastText) {
      lastText = text;
      ctx.setText(text);
    }
  };

  const events: MuoviLinkEvents = {
    samples(raw) {
      if ((n + 1) * k > batch.length) {
        const bigger = new Float64Array(batch.length * 2);
        bigger.set(batch);
        batch = bigger;
      }
      o.convert(raw, batch, n * k);
      n++;
    },
    chunkEnd() {
      if (n === 0) return;
      const f = out.frame(n);
      clock.stamp(ctx.now(), f.t, n);
      f.v.set(batch.subarray(0, n * k));
      out.emit(f);
      emitted += n;
      n = 0;
      if (throttle.due(ctx.now())) refresh();
    },
    state(p, text) {
      if (p !== "streaming") {
        clock.restart();
        n = 0;
      }
      phase = text;
      refresh();
    },
    warn: (m) => ctx.warn(m),
  };

  refresh();
  return {
    start() {
      if (!o.available(ctx)) {
        phase = "TCP not available in the browser build; use --simulate-devices";
        refresh();
        ctx.warn(noTcpMessage(o.target));
        return;
      }
      link = o.open(ctx, events);
    },
    stop() {
      link?.close();
      link = undefined;
      phase = "stopped";
      refresh();
    },
    reset() {
      clock.reset();
      emitted = 0;
      throttle.reset();
      refresh();
    },
    dispose() {
      link?.close();
      link = undefined;
    },
  };
}
