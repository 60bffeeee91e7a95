/**
 * What the TCP links to streaming devices share (docs/protocols.md): OT Bioelettronica's
 * SyncStation, Muovi probes, Sessantaquattro and Quattrocento, and the retry policy of the Delsys
 * link.
 *
 * - `StreamLink`: the parser of the device's sample stream, its counts (samples, samples the
 *   device skipped, malformed data, connections that ended inside a sample, reconnections), a
 *   heartbeat that drops a connection silent for `SILENCE` s, and the retries: a refused or lost
 *   connection is closed, said (state and one warning) and tried again after 0.5 s, 1 s, 2 s, 4 s,
 *   then every 5 s. A subclass says how to connect (`attempt`), how to close (`drop`) and what to
 *   show.
 * - `retryWait` and `failureHead`: the same policy and wording for links with their own session
 *   logic (TrignoLink).
 * - `nativeStreamSource`: a block without an input that is its own source at the device's rate,
 *   the samples of each TCP chunk emitted as one frame on the device's sample clock.
 */
import {
  vectorShape,
  type BlockContext,
  type BlockInstance,
  type OutputPort,
  type PortMeta,
  type TcpBridge,
} from "../../engine";
import { plural, TextThrottle } from "../shared/text";
import { DeviceClock } from "./delsys-protocol";

/** Seconds without data after which a connection counts as lost. */
export const SILENCE = 2;
/** Waits between attempts, s: doubling from the first up to the last. */
export const RETRY_FIRST = 0.5;
export const RETRY_MAX = 5;
/** How often the link looks at its deadlines, s. */
const HEARTBEAT = 0.1;

export type LinkPhase = "connecting" | "streaming" | "lost";

export interface LinkEvents<Raw = Int16Array> {
  /** One sample's raw values (all channels on the wire; valid during the call). */
  samples(raw: Raw): void;
  state(phase: LinkPhase, text: string): void;
  warn(message: string): void;
  /** The samples of one TCP chunk have all been given (the native form emits them as a frame). */
  chunkEnd?(): void;
}

export interface LinkCounts {
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

/** A parser of a device's sample stream, as the links count it. */
export interface StreamParser {
  /** Bytes of one sample on the wire. */
  readonly sampleBytes: number;
  readonly samples: number;
  /** Samples the device skipped (its counter jumped ahead); 0 where the stream has no counter. */
  readonly lostSamples: number;
  /** Times the counter restarted (or jumped too far to count the samples in between). */
  readonly counterJumps: number;
  readonly malformed: number;
  readonly skippedBytes: number;
  readonly lastProblem: string;
  feed(chunk: Uint8Array): void;
  /** Forgets what is held (a new connection); returns the bytes dropped. */
  reset(): number;
}

/** The wait before attempt `failures + 1`, s: 0.5, 1, 2, 4, then every 5. */
export function retryWait(failures: number): number {
  return Math.min(RETRY_MAX, RETRY_FIRST * 2 ** (failures - 1));
}

/** How a failure reads in the status: "lost X: …", "still lost: …" or "not reachable: …". */
export function failureHead(
  target: string,
  reason: string,
  everStreamed: boolean,
  wasStreaming: boolean,
): string {
  if (!everStreamed) return `not reachable: ${reason}`;
  return wasStreaming ? `lost ${target}: ${reason}` : `still lost: ${reason}`;
}

/** "connecting to X…", with the attempt after the first. */
export function connectingText(target: string, failures: number): string {
  return failures > 0
    ? `connecting to ${target} (attempt ${failures + 1})…`
    : `connecting to ${target}…`;
}

/** What every link shares: the parser, the counts, the heartbeat, retries. */
export abstract class StreamLink<Raw = Int16Array> {
  protected gen = 0;
  protected closed = true;
  protected streaming = false;
  protected everStreamed = false;
  protected lastData = 0;
  protected retryAt = -1;
  protected readonly parser: StreamParser;
  readonly counts: LinkCounts = {
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
    makeParser: (onSample: (raw: Raw) => void) => StreamParser,
    protected readonly ev: LinkEvents<Raw>,
  ) {
    this.parser = makeParser((raw) => ev.samples(raw));
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
    const wait = retryWait(this.counts.failures);
    const head = failureHead(this.target, reason, this.everStreamed, wasStreaming);
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

/** The sentence for a host without TCP (the browser build). */
export function noTcpMessage(target: string): string {
  return `TCP not available in the browser build; use --simulate-devices (or the app's Simulate devices switch): ${target} cannot be reached and this block sends zeros`;
}

/** One line of counts, for the blocks' `counts` action. */
export function linkCountsText(c: LinkCounts | undefined): string {
  if (!c) return "not started";
  return (
    `${c.samples} samples, ${c.lostSamples} skipped by the device, ${c.counterJumps} counter restarts, ${c.reconnections} reconnections, ` +
    `${c.malformed} malformed (${c.skippedBytes} bytes skipped${c.lastProblem ? `, last: ${c.lastProblem}` : ""}), ` +
    `${c.truncated} truncated (${c.truncatedBytes} bytes)`
  );
}

export interface NativeStreamOptions<Raw = Int16Array> {
  /** The device's sample rate, Hz. */
  rate: number;
  /** What the channels are (names, unit, electrode grid), for panels and recorders. */
  meta?: PortMeta;
  /** How far ahead of arrival a frame's stamps may run, s (about one packet of the device). */
  maxLead: number;
  /** Output channels (vector [1, channels] per sample). */
  channels: number;
  /** "the SyncStation at …", for the no-TCP message. */
  target: string;
  /** Whether this host can reach the device (a TCP bridge, with listen when needed). */
  available(ctx: BlockContext): boolean;
  /** Opens the link with these events (the bridge is available). */
  open(ctx: BlockContext, ev: LinkEvents<Raw>): { close(): void };
  /** Writes one sample's output values from its raw values at `out[at…]`. */
  convert(raw: Raw, out: Float64Array, at: number): void;
}

/**
 * The blocks without an input: their own source at the device's rate. The samples of each TCP
 * chunk go out at once as one frame, stamped on the device's sample clock (the first batch's last
 * sample at its arrival, then 1 / rate s apart, at most `maxLead` ahead of arrival; re-anchored
 * after a loss, the gap counted).
 */
export function nativeStreamSource<Raw = Int16Array>(
  ctx: BlockContext,
  o: NativeStreamOptions<Raw>,
): BlockInstance {
  return new NativeStreamRun(ctx, o).instance();
}

/** The state of one native source: the batch of the current chunk, the clock and the status. */
class NativeStreamRun<Raw> {
  private readonly k: number;
  private readonly out: OutputPort;
  private readonly clock: DeviceClock;
  private readonly throttle = new TextThrottle(0.5);
  private batch: Float64Array;
  private n = 0;
  private emitted = 0;
  private phase = "stopped";
  private lastText = "";
  private link: { close(): void } | undefined;
  /** What the link calls, made once. */
  private readonly events: LinkEvents<Raw>;

  constructor(
    private readonly ctx: BlockContext,
    private readonly o: NativeStreamOptions<Raw>,
  ) {
    if (ctx.declaredRate === undefined) ctx.setDesiredRate(o.rate);
    this.k = o.channels;
    this.out = ctx.output(vectorShape(this.k), "emg", o.meta);
    this.clock = new DeviceClock(o.rate, 0.5, o.maxLead);
    this.batch = new Float64Array(64 * this.k);
    this.events = {
      samples: (raw) => this.add(raw),
      chunkEnd: () => this.emitChunk(),
      state: (p, text) => this.linkState(p, text),
      warn: (m) => ctx.warn(m),
    };
    this.refresh();
  }

  /** The block instance the engine drives. */
  instance(): BlockInstance {
    return {
      start: () => this.start(),
      stop: () => this.stop(),
      reset: () => this.reset(),
      dispose: () => this.dispose(),
    };
  }

  /** The status: the link's phase, the samples emitted and those lost in gaps, when it changed. */
  private refresh(): void {
    let text = this.phase;
    if (this.emitted > 0) text += ` · ${plural(this.emitted, "sample")}`;
    if (this.clock.gapSamples > 0) text += ` · ${this.clock.gapSamples} samples lost in gaps`;
    if (text !== this.lastText) {
      this.lastText = text;
      this.ctx.setText(text);
    }
  }

  /** One sample of the chunk, converted into the batch (doubled when full). */
  private add(raw: Raw): void {
    const k = this.k;
    if ((this.n + 1) * k > this.batch.length) {
      const bigger = new Float64Array(this.batch.length * 2);
      bigger.set(this.batch);
      this.batch = bigger;
    }
    this.o.convert(raw, this.batch, this.n * k);
    this.n++;
  }

  /** The chunk ended: its samples go out as one frame on the device's clock. */
  private emitChunk(): void {
    const n = this.n;
    if (n === 0) return;
    const f = this.out.frame(n);
    this.clock.stamp(this.ctx.now(), f.t, n);
    f.v.set(this.batch.subarray(0, n * this.k));
    this.out.emit(f);
    this.emitted += n;
    this.n = 0;
    if (this.throttle.due(this.ctx.now())) this.refresh();
  }

  /** The link's phase changed: out of streaming, the clock restarts and the batch is dropped. */
  private linkState(p: LinkPhase, text: string): void {
    if (p !== "streaming") {
      this.clock.restart();
      this.n = 0;
    }
    this.phase = text;
    this.refresh();
  }

  /** Opens the link, or says that this host has no TCP. */
  private start(): void {
    if (!this.o.available(this.ctx)) {
      this.phase = "TCP not available in the browser build; use --simulate-devices";
      this.refresh();
      this.ctx.warn(noTcpMessage(this.o.target));
      return;
    }
    this.link = this.o.open(this.ctx, this.events);
  }

  /** Closes the link and says so. */
  private stop(): void {
    this.link?.close();
    this.link = undefined;
    this.phase = "stopped";
    this.refresh();
  }

  /** Forgets the clock and the count of samples emitted. */
  private reset(): void {
    this.clock.reset();
    this.emitted = 0;
    this.throttle.reset();
    this.refresh();
  }

  /** Closes the link. */
  private dispose(): void {
    this.link?.close();
    this.link = undefined;
  }
}
