/**
 * A device simulator's sample stream on a TCP socket: samples go out as the wall clock makes them
 * due (from the moment the stream started), in whole packets, and the faults the tests ask for —
 * bytes injected between two samples, samples skipped (the counter jumps), half a sample then a
 * dropped connection — happen on the next write. A client that stops reading loses samples
 * (counted in `dropped`) instead of growing the socket's buffer without end.
 */
import type { Socket } from "node:net";

/** What the stream sends: its rate and its samples' bytes. */
export interface PacedSource {
  /** Samples per second. */
  readonly rate: number;
  /** Samples in one packet: a write holds a whole number of them. */
  readonly packetSamples: number;
  /** The bytes of samples k0 … k0 + n − 1, as the device writes them. */
  encode(k0: number, n: number): Buffer;
}

export interface PacedStreamOptions {
  /** How often to look whether samples are due, ms. */
  pumpMs: number;
  /** Bytes the client may leave unread before samples to it are dropped. */
  maxUnread: number;
}

export class PacedSampleStream<S extends PacedSource = PacedSource> {
  private k = 0;
  private sent = 0;
  private t0 = 0;
  private timer: NodeJS.Timeout | undefined;
  private pendingInject: Buffer[] = [];
  private pendingSkip = 0;
  private pendingTruncate = false;
  /** Samples not sent because the client did not read (`maxUnread`). */
  dropped = 0;

  constructor(
    private readonly socket: Socket,
    readonly source: S,
    private readonly o: PacedStreamOptions,
  ) {}

  /** Samples sent, skipped or dropped since the start. */
  get samples(): number {
    return this.k;
  }

  /** When the stream (re)started, performance.now() ms: samples never run ahead of it. */
  get startedAt(): number {
    return this.t0;
  }

  get running(): boolean {
    return this.timer !== undefined;
  }

  /** Starts (again) from sample 0 now. */
  start(): void {
    this.stop();
    this.k = 0;
    this.sent = 0;
    this.t0 = performance.now();
    this.timer = setInterval(() => this.pump(), this.o.pumpMs);
  }

  stop(): void {
    if (this.timer) clearInterval(this.timer);
    this.timer = undefined;
  }

  /** These bytes go out between two samples of the next write. */
  inject(bytes: Uint8Array): void {
    this.pendingInject.push(Buffer.from(bytes));
  }

  /** n samples are never sent (the counter jumps by n). */
  skip(n: number): void {
    this.pendingSkip += n;
  }

  /** Half a sample goes out, then the connection drops. */
  truncate(): void {
    this.pendingTruncate = true;
  }

  /** Samples due now, in whole packets. */
  private due(): number {
    const { rate, packetSamples } = this.source;
    const due = Math.floor(((performance.now() - this.t0) / 1000) * rate) - this.sent;
    return due - (due % packetSamples);
  }

  private pump(): void {
    const s = this.socket;
    if (s.destroyed) {
      this.stop();
      return;
    }
    const n = this.due();
    if (n < 1) return;
    this.sent += n;
    if (this.pendingTruncate) {
      this.truncateNow(s);
      return;
    }
    this.k += this.pendingSkip;
    this.pendingSkip = 0;
    if (s.writableLength > this.o.maxUnread) {
      this.k += n;
      this.dropped += n;
      return;
    }
    s.write(this.packet(n));
  }

  /** n samples from k, with the injected bytes between their two halves. */
  private packet(n: number): Buffer {
    const half = Math.floor(n / 2);
    const parts = [this.source.encode(this.k, half), ...this.pendingInject.splice(0)];
    parts.push(this.source.encode(this.k + half, n - half));
    this.k += n;
    return Buffer.concat(parts);
  }

  private truncateNow(s: Socket): void {
    this.pendingTruncate = false;
    const one = this.source.encode(this.k, 1);
    this.stop();
    s.write(one.subarray(0, Math.floor(one.length / 2)), () => s.destroy());
  }
}
