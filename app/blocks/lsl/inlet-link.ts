/**
 * The inlet side shared by LslInlet and LslMarkerInlet: resolve a stream by predicate (a
 * continuous resolver, never waiting), open an inlet, wait for liblsl's first clock offset
 * (samples pulled meanwhile are held, not lost), pull on every poll, map each sample's timestamp
 * onto the pipeline clock, and notice a lost stream (liblsl's lost error, or silence of a regular
 * stream) and its recovery. All state is in the status line.
 */
import type {
  BlockContext,
  LslBridge,
  LslInletHandle,
  LslResolverHandle,
  LslStreamInfo,
} from "../../engine";
import { formatCount } from "../shared/text";
import { ClockMap, LatencyStats, measureOffset, senderToPipeline } from "./clock-map";
import { CLOCK_CHECK_S, describeStream, ms } from "./lsl-common";

/** How often the resolver's list is read while looking for the stream, s. */
const RESOLVE_EVERY_S = 0.25;
/**
 * How long a new resolver looks before a stream is chosen, s: liblsl recommends resolving for
 * 1 s, a shorter wait may list "only a subset (or none) of the outlets" (`resolver.h`), and the
 * choice among several matches should see them all.
 */
const RESOLVE_SETTLE_S = 1;
/** How often liblsl's time correction is read, s. */
const CORRECTION_EVERY_S = 1;
/** How long samples wait for the first time correction before they go out uncorrected, s. */
const CLOCK_WAIT_S = 2;
/** Samples read per pull call. */
const PULL_SAMPLES = 1024;

export interface InletLinkOptions {
  predicate: string;
  /** The output's width: streams with another channel count are refused (with a message). */
  channels: number;
  /** True for a marker inlet: string streams are read as strings. */
  acceptStrings: boolean;
  bufferS: number;
  recover: boolean;
  /** Samples pulled, timestamps already on the pipeline clock (valid during the call). */
  onSamples(
    n: number,
    values: Float64Array,
    strings: readonly string[] | undefined,
    times: Float64Array,
  ): void;
}

type State = "resolving" | "clock" | "streaming" | "failed" | "closed";

interface Held {
  n: number;
  values: Float64Array;
  strings: string[] | undefined;
  remote: Float64Array;
}

export class InletLink {
  state: State = "resolving";
  stream: LslStreamInfo | undefined;
  samples = 0;
  chunks = 0;
  lost = 0;
  recovered = 0;
  refused = "";
  failure = "";
  readonly latency = new LatencyStats();
  correction = 0;
  correctionUncertainty = Number.NaN;
  readonly clock = new ClockMap();
  private silent = false;
  private lsl: LslBridge | undefined;
  private resolver: LslResolverHandle | undefined;
  private inlet: LslInletHandle | undefined;
  private lastResolve = Number.NEGATIVE_INFINITY;
  private resolveFrom = Number.NaN;
  private lastCorrection = Number.NEGATIVE_INFINITY;
  private lastClockCheck = Number.NEGATIVE_INFINITY;
  private clockWaitFrom = 0;
  private lastSampleAt = 0;
  private held: Held[] = [];
  private values = new Float64Array(0);
  private remote = new Float64Array(PULL_SAMPLES);
  private times = new Float64Array(PULL_SAMPLES);
  private strings: string[] = [];

  constructor(
    private readonly ctx: BlockContext,
    private readonly o: InletLinkOptions,
  ) {}

  /** Starts resolving; false (with the reason in `failure`) when LSL cannot be used. */
  start(lsl: LslBridge): boolean {
    this.lsl = lsl;
    try {
      this.clock.adopt(
        measureOffset(
          () => this.ctx.now(),
          () => lsl.localClock(),
        ),
      );
      this.resolver = lsl.resolve(this.o.predicate);
      this.state = "resolving";
      return true;
    } catch (e) {
      this.fail(e);
      return false;
    }
  }

  private fail(e: unknown): void {
    this.state = "failed";
    this.failure = e instanceof Error ? e.message : String(e);
  }

  /** One poll at pipeline time `now`: resolve, open, pull. */
  poll(now: number): void {
    try {
      if (this.state === "resolving") this.resolveStep(now);
      if (this.state === "clock") this.clockStep(now);
      if (this.state === "streaming") this.streamStep(now);
    } catch (e) {
      this.fail(e);
      this.closeInlet();
    }
  }

  private resolveStep(now: number): void {
    if (!this.resolver || now - this.lastResolve < RESOLVE_EVERY_S) return;
    if (Number.isNaN(this.resolveFrom)) this.resolveFrom = now;
    if (now - this.resolveFrom < RESOLVE_SETTLE_S) return;
    this.lastResolve = now;
    const found = this.resolver.results();
    const usable = found.filter((s) => this.fits(s));
    if (usable.length === 0) return;
    const stream = usable[0]!;
    if (usable.length > 1) {
      this.ctx.warn(
        `${usable.length} streams match ${this.o.predicate}: reading the one on ${stream.hostname ?? "?"} (source id '${stream.sourceId}'); narrow it with SourceId or a Predicate`,
      );
    }
    this.inlet = this.resolver.openInlet(stream, {
      bufferS: this.o.bufferS,
      recover: this.o.recover,
    });
    this.refused = "";
    this.stream = stream;
    this.checkRate(stream);
    if (this.lost > 0) this.recovered++;
    this.state = "clock";
    this.clockWaitFrom = now;
    this.lastCorrection = Number.NEGATIVE_INFINITY;
  }

  /** Warns when the stream's nominal rate is not the block's DesiredRate (what downstream assumes). */
  private checkRate(s: LslStreamInfo): void {
    const want = this.ctx.desiredRate;
    if (want > 0 && s.rate > 0 && Math.abs(want - s.rate) > 1e-6 * s.rate) {
      this.ctx.warn(
        `stream '${s.name}' has a nominal rate of ${s.rate} Hz; this block's DesiredRate is ${want} Hz`,
      );
    }
  }

  /** True when the stream can feed this block; otherwise says why in `refused`. */
  private fits(s: LslStreamInfo): boolean {
    const where = `stream '${s.name}' (${s.type}) on ${s.hostname ?? "?"}`;
    if (s.format === "other") {
      this.refused = `${where} has a format this block cannot read (int8 or int64)`;
    } else if (s.format === "string" && !this.o.acceptStrings) {
      this.refused = `${where} is a string (marker) stream: read it with LslMarkerInlet`;
    } else if (s.channels !== this.o.channels) {
      this.refused = `${where} has ${s.channels} channels; Channels is ${this.o.channels}`;
    } else return true;
    return false;
  }

  private readCorrection(now: number): boolean {
    if (now - this.lastCorrection < CORRECTION_EVERY_S) return false;
    const tc = this.inlet?.timeCorrection();
    if (!tc) return false;
    this.lastCorrection = now;
    this.correction = tc.offset;
    this.correctionUncertainty = tc.uncertainty;
    return true;
  }

  /** Holds what arrives until liblsl has the sender's clock offset (or CLOCK_WAIT_S passed). */
  private clockStep(now: number): void {
    const got = this.readCorrection(now);
    if (!got && now - this.clockWaitFrom < CLOCK_WAIT_S) {
      this.pullInto((n, values, strings, remote) => {
        this.held.push({
          n,
          values: values.slice(0, n * this.o.channels),
          strings: strings?.slice(),
          remote: remote.slice(0, n),
        });
      });
      return;
    }
    if (!got) {
      this.ctx.warn(
        `no clock offset from '${this.stream?.name}' after ${CLOCK_WAIT_S} s: timestamps are the sender's, uncorrected`,
      );
    }
    this.state = "streaming";
    this.lastSampleAt = now;
    // Held samples waited for the clock, not for the network: they stay out of the latency.
    for (const h of this.held.splice(0))
      this.deliver(h.n, h.values, h.strings, h.remote, now, false);
  }

  private streamStep(now: number): void {
    if (now - this.lastClockCheck >= CLOCK_CHECK_S && !this.ctx.virtual && this.lsl) {
      this.lastClockCheck = now;
      const lsl = this.lsl;
      this.clock.adopt(
        measureOffset(
          () => this.ctx.now(),
          () => lsl.localClock(),
        ),
      );
    }
    this.readCorrection(now);
    const any = this.pullInto((n, values, strings, remote) =>
      this.deliver(n, values, strings, remote, now),
    );
    if (this.state !== "streaming") return;
    if (any) {
      this.lastSampleAt = now;
      if (this.silent) {
        this.silent = false;
        this.recovered++;
      }
    } else if (!this.silent && this.silenceTooLong(now)) {
      this.silent = true;
      this.lost++;
      this.ctx.warn(
        `stream '${this.stream?.name}' lost: no sample for ${ms(now - this.lastSampleAt)}`,
      );
    }
  }

  /** A regular stream is lost after 1 s or 20 periods without a sample, whichever is longer. */
  private silenceTooLong(now: number): boolean {
    const rate = this.stream?.rate ?? 0;
    return rate > 0 && now - this.lastSampleAt > Math.max(1, 20 / rate);
  }

  /** Pulls everything buffered, chunk by chunk; false when nothing came. */
  private pullInto(
    take: (
      n: number,
      values: Float64Array,
      strings: string[] | undefined,
      remote: Float64Array,
    ) => void,
  ): boolean {
    const inlet = this.inlet;
    if (!inlet || !this.stream) return false;
    const strings = this.stream.format === "string";
    const width = this.o.channels;
    if (this.values.length < PULL_SAMPLES * width)
      this.values = new Float64Array(PULL_SAMPLES * width);
    let any = false;
    for (;;) {
      const n = strings
        ? inlet.pullStrings(this.strings, this.remote, PULL_SAMPLES)
        : inlet.pull(this.values, this.remote, PULL_SAMPLES);
      if (n < 0) {
        this.onLost();
        return any;
      }
      if (n === 0) return any;
      any = true;
      take(n, this.values, strings ? this.strings : undefined, this.remote);
      if (n < PULL_SAMPLES) return any;
    }
  }

  private deliver(
    n: number,
    values: Float64Array,
    strings: string[] | undefined,
    remote: Float64Array,
    now: number,
    timed = true,
  ): void {
    const times = this.times.length >= n ? this.times : (this.times = new Float64Array(n));
    for (let i = 0; i < n; i++)
      times[i] = senderToPipeline(remote[i]!, this.correction, this.clock);
    this.samples += n;
    this.chunks++;
    if (timed) this.latency.add(now - times[n - 1]!);
    this.o.onSamples(n, values, strings, times);
  }

  /** liblsl gave up on the stream (no source id to recover it by): resolve it again. */
  private onLost(): void {
    this.lost++;
    this.ctx.warn(`stream '${this.stream?.name}' lost: resolving it again`);
    this.closeInlet();
    this.silent = false;
    this.state = "resolving";
    this.lastResolve = Number.NEGATIVE_INFINITY;
  }

  private closeInlet(): void {
    this.inlet?.close();
    this.inlet = undefined;
    this.held.length = 0;
  }

  close(): void {
    this.closeInlet();
    this.resolver?.close();
    this.resolver = undefined;
    this.state = "closed";
  }

  /** One status line. */
  text(): string {
    if (this.state === "failed") return this.failure;
    const s = this.stream;
    if (this.state === "resolving" || !s) {
      const base = `looking for an LSL stream where ${this.o.predicate}`;
      return this.refused ? `${base}; ${this.refused}` : base;
    }
    const parts = [
      `${this.silent ? "lost" : this.state === "clock" ? "syncing with" : "receiving"} '${s.name}' from ${s.hostname ?? "?"} (${describeStream(s)})`,
      `${formatCount(this.samples)} samples`,
    ];
    if (this.latency.n > 0) {
      parts.push(`latency ${ms(this.latency.mean)} ± ${ms(this.latency.jitter)} (jitter)`);
    }
    parts.push(`clock offset ${ms(this.correction)}`);
    if (this.lost > 0) parts.push(`lost ${this.lost}×, recovered ${this.recovered}×`);
    return parts.join(", ");
  }
}
