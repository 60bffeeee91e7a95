/**
 * The connection to a Trigno Control Utility's SDK server (docs/protocols.md, "Delsys Trigno"),
 * over the host's TCP bridge (`ctx.io.tcp`): connect the command port and read its banner, switch
 * backwards compatibility and upsampling off (the native 1925.926 Hz), ask which of the selected
 * sensors are paired and of what type, read the frame interval and samples per frame (the rate),
 * connect the EMG data port, send START, then parse the float32 stream (delsys-protocol.ts) and
 * hand the selected sensors' values over in the batches they arrived in. A failure at any step
 * (refused, closed, a reply missing for `REPLY_TIMEOUT` s) closes both connections, says why, and
 * tries again after 0.5 s, 1 s, 2 s, 4 s, then every 5 s (stream-link.ts's policy); `close` sends
 * STOP first.
 *
 * `delsysProtocol` wraps it as the `DeviceProtocol` of the timer-paced form (paced-device.ts).
 */
import type { BlockContext, TcpBridge, TcpSocketHandle } from "../../engine";
import type { DeviceProtocol, DeviceSampleSink } from "./paced-device";
import { TrignoAuxJoin } from "./delsys-aux";
import {
  hzText,
  TRIGNO_AUX,
  TRIGNO_AUX_PORT,
  TRIGNO_AUX_SAMPLES,
  TRIGNO_FRAME_INTERVAL,
  TRIGNO_NATIVE_RATE,
  TRIGNO_NATIVE_SAMPLES,
  TRIGNO_SAMPLE_BYTES,
  TRIGNO_TERMINATOR,
  TrignoEmgParser,
} from "./delsys-protocol";
import { connectingText, failureHead, noTcpMessage, retryWait } from "./stream-link";

/** Seconds a command may wait for its reply (and the connection for its banner). */
export const REPLY_TIMEOUT = 3;
/** What to do without the device (said once, when the first attempt fails). */
export const NO_DEVICE_HINT =
  "retrying until it answers (without the device: mosaic run --simulate-devices, or a simulated TCU: mosaic simulate delsys)";
/** Longest reply or banner kept, characters (a peer that is not a TCU sends anything). */
const MAX_REPLY = 4096;

export interface TrignoLinkOptions {
  host: string;
  commandPort: number;
  emgPort: number;
  /** Selected sensors (1…16), in output order. */
  sensors: readonly number[];
  /**
   * AUX values joined per sensor after its EMG value (0: the AUX port is not used; 3: the
   * accelerometer; 9: accelerometer, gyroscope, magnetometer), from `auxPort`.
   */
  aux?: number;
  auxPort?: number;
}

/** Output values per sample: per sensor its EMG value and its AUX values. */
export const trignoWidth = (o: TrignoLinkOptions): number => o.sensors.length * (1 + (o.aux ?? 0));

export type TrignoPhase = "connecting" | "streaming" | "lost";

export interface TrignoLinkEvents {
  /** `n` samples of `trignoWidth` values each (row-major in `values`, valid during the call). */
  samples(values: Float64Array, n: number): void;
  /** The link's state in a few words. */
  state(phase: TrignoPhase, text: string): void;
  warn(message: string): void;
  /** Streaming began at `rate` Hz; `reconnected` after a loss. */
  started?(rate: number, reconnected: boolean): void;
  /** The stream broke (before the next `started`). */
  broke?(): void;
}

/** What the link knows and counted (for the status and the `counts` action). */
export interface TrignoCounts {
  samples: number;
  malformed: number;
  skippedBytes: number;
  lastProblem: string;
  /** Connections that ended inside a sample, and the bytes lost that way. */
  truncated: number;
  truncatedBytes: number;
  /** Times streaming began again after a loss. */
  reconnections: number;
  /** Failed attempts since the last success. */
  failures: number;
  rate: number;
  banner: string;
  /** Selected sensors the TCU says are not paired. */
  unpaired: number[];
  /** Sensor types as the TCU gave them, by sensor number. */
  types: Record<number, string>;
  /** The AUX stream (when used): samples, malformed, and what the join held or dropped. */
  aux: { samples: number; malformed: number; held: number; dropped: number; perFrame: number };
}

class LinkError extends Error {}

/** A reply that is not what the command expects: its text, quoted. */
const quote = (s: string): string => JSON.stringify(s.length > 80 ? s.slice(0, 80) + "…" : s);

export class TrignoLink {
  private gen = 0;
  private cmd: TcpSocketHandle | undefined;
  private data: TcpSocketHandle | undefined;
  private cmdOpen = false;
  private started = false;
  private everStreamed = false;
  private closed = true;
  private text = "";
  private readonly replies: string[] = [];
  private waiting: { resolve: (r: string) => void; reject: (e: Error) => void } | undefined;
  private deadline = 0;
  private readonly parser: TrignoEmgParser;
  private readonly slots: Int32Array;
  private batch: Float64Array;
  private batchN = 0;
  readonly counts: TrignoCounts = {
    samples: 0,
    malformed: 0,
    skippedBytes: 0,
    lastProblem: "",
    truncated: 0,
    truncatedBytes: 0,
    reconnections: 0,
    failures: 0,
    rate: TRIGNO_NATIVE_RATE,
    banner: "",
    unpaired: [],
    types: {},
    aux: { samples: 0, malformed: 0, held: 0, dropped: 0, perFrame: TRIGNO_AUX_SAMPLES },
  };
  private auxSock: TcpSocketHandle | undefined;
  private readonly auxParser: TrignoEmgParser | undefined;
  private readonly join: TrignoAuxJoin | undefined;

  constructor(
    private readonly ctx: BlockContext,
    private readonly tcp: TcpBridge,
    private readonly o: TrignoLinkOptions,
    private readonly ev: TrignoLinkEvents,
  ) {
    this.slots = Int32Array.from(o.sensors, (s) => s - 1);
    this.batch = new Float64Array(64 * o.sensors.length);
    this.parser = new TrignoEmgParser((v) => this.onSample(v));
    if ((o.aux ?? 0) > 0) {
      this.join = new TrignoAuxJoin(this.slots, o.aux!, TRIGNO_NATIVE_SAMPLES, TRIGNO_AUX_SAMPLES);
      const join = this.join;
      this.auxParser = new TrignoEmgParser((v) => join.pushAux(v), TRIGNO_AUX);
    }
  }

  get options(): TrignoLinkOptions {
    return this.o;
  }

  /** "the Trigno Control Utility at 127.0.0.1:50040". */
  get target(): string {
    const h = this.o.host.includes(":") ? `[${this.o.host}]` : this.o.host;
    return `the Trigno Control Utility at ${h}:${this.o.commandPort}`;
  }

  open(): void {
    if (!this.closed) return;
    this.closed = false;
    this.counts.failures = 0;
    this.attempt();
  }

  /** Sends STOP when streaming, closes both connections; no event follows. */
  close(): void {
    if (this.closed) return;
    this.closed = true;
    this.teardown(true);
  }

  private onSample(v: Float64Array): void {
    if (this.join) {
      this.join.pushEmg(v);
      return;
    }
    const k = this.slots.length;
    if ((this.batchN + 1) * k > this.batch.length) {
      const bigger = new Float64Array(this.batch.length * 2);
      bigger.set(this.batch);
      this.batch = bigger;
    }
    const at = this.batchN * k;
    for (let i = 0; i < k; i++) this.batch[at + i] = v[this.slots[i]!]!;
    this.batchN++;
  }

  private syncCounts(): void {
    const c = this.counts;
    c.samples = this.parser.samples;
    c.malformed = this.parser.malformed;
    c.skippedBytes = this.parser.skippedBytes;
    c.lastProblem = this.parser.lastProblem;
  }

  private onData(gen: number, chunk: Uint8Array): void {
    if (gen !== this.gen || !this.started) return;
    const malformedBefore = this.parser.malformed;
    this.batchN = 0;
    this.parser.feed(chunk);
    this.syncCounts();
    if (this.parser.malformed > malformedBefore) {
      this.ev.warn(
        `malformed EMG data from ${this.target} (${this.counts.lastProblem}): skipping to the next whole sample (${this.counts.malformed} so far)`,
      );
    }
    if (this.join) this.emitJoined();
    else if (this.batchN > 0) this.ev.samples(this.batch, this.batchN);
  }

  private onAuxData(gen: number, chunk: Uint8Array): void {
    const p = this.auxParser;
    if (gen !== this.gen || !this.started || !p) return;
    const before = p.malformed;
    p.feed(chunk);
    this.counts.aux.samples = p.samples;
    this.counts.aux.malformed = p.malformed;
    if (p.malformed > before) {
      this.ev.warn(
        `malformed AUX data from ${this.target} (${p.lastProblem}): skipping to the next whole sample (${p.malformed} so far)`,
      );
    }
    this.emitJoined();
  }

  /** Every EMG sample whose AUX sample came, joined. */
  private emitJoined(): void {
    const { values, n } = this.join!.drain();
    this.counts.aux.held = this.join!.counts.held;
    this.counts.aux.dropped = this.join!.counts.dropped;
    if (n > 0) this.ev.samples(values, n);
  }

  /** Drops the connections (STOP first when asked and possible). */
  private teardown(stop: boolean): void {
    this.gen++;
    const wasStarted = this.started;
    this.started = false;
    if (this.cmd && this.cmdOpen && stop && wasStarted) this.cmd.write(`STOP${TRIGNO_TERMINATOR}`);
    this.cmd?.close();
    this.data?.close();
    this.auxSock?.close();
    this.cmd = undefined;
    this.data = undefined;
    this.auxSock = undefined;
    this.auxParser?.reset();
    this.cmdOpen = false;
    this.replies.length = 0;
    this.text = "";
    const w = this.waiting;
    this.waiting = undefined;
    w?.reject(new LinkError("closed"));
    const held = this.parser.reset();
    if (held > 0 && wasStarted) {
      this.counts.truncated++;
      this.counts.truncatedBytes += held;
      if (!this.closed) {
        this.ev.warn(
          held < TRIGNO_SAMPLE_BYTES
            ? `the EMG stream from ${this.target} ended inside a sample (${held} of ${TRIGNO_SAMPLE_BYTES} bytes): dropped`
            : `the EMG stream from ${this.target} ended while realigning (${held} bytes held): dropped`,
        );
      }
    }
    if (wasStarted) this.ev.broke?.();
  }

  /** Something failed: close, say why, try again later. */
  private fail(gen: number, reason: string): void {
    if (gen !== this.gen || this.closed) return;
    const wasStreaming = this.started;
    this.teardown(false);
    this.counts.failures++;
    const wait = retryWait(this.counts.failures);
    const head = failureHead(this.target, reason, this.everStreamed, wasStreaming);
    this.ev.state("lost", `${head}; retrying in ${wait} s (attempt ${this.counts.failures + 1})`);
    if (wasStreaming) this.ev.warn(`lost ${this.target}: ${reason}; reconnecting`);
    else if (this.counts.failures === 1 && !this.everStreamed) {
      this.ev.warn(`${this.target} ${head}; ${NO_DEVICE_HINT}`);
    }
    const retry = this.gen;
    this.ctx.at(this.ctx.now() + wait, () => {
      if (retry === this.gen && !this.closed) this.attempt();
    });
  }

  private attempt(): void {
    const gen = ++this.gen;
    this.ev.state("connecting", connectingText(this.target, this.counts.failures));
    this.cmd = this.tcp.connect(
      { host: this.o.host, port: this.o.commandPort },
      {
        onConnect: () => {
          if (gen !== this.gen) return;
          this.cmdOpen = true;
        },
        onData: (d) => this.onCommandData(gen, d),
        onClose: (reason, wasOpen) =>
          this.fail(gen, wasOpen ? `the command connection ended: ${reason}` : reason),
      },
      { timeoutMs: REPLY_TIMEOUT * 1000 },
    );
    this.session(gen).catch((e: unknown) => {
      if (e instanceof LinkError && e.message === "closed") return;
      this.fail(gen, e instanceof Error ? e.message : String(e));
    });
  }

  private onCommandData(gen: number, d: Uint8Array): void {
    if (gen !== this.gen) return;
    for (let i = 0; i < d.length; i++) this.text += String.fromCharCode(d[i]!);
    for (let end = this.text.indexOf(TRIGNO_TERMINATOR); end >= 0;) {
      const reply = this.text.slice(0, end).trim();
      this.text = this.text.slice(end + TRIGNO_TERMINATOR.length);
      const w = this.waiting;
      if (w) {
        this.waiting = undefined;
        w.resolve(reply);
      } else this.replies.push(reply);
      end = this.text.indexOf(TRIGNO_TERMINATOR);
    }
    if (this.text.length > MAX_REPLY) {
      this.fail(
        gen,
        `the command port sent ${this.text.length} characters without "\\r\\n\\r\\n": is this a Trigno Control Utility?`,
      );
    }
  }

  /** The next message on the command port (the banner, or a reply), or an error after REPLY_TIMEOUT. */
  private next(gen: number, what: string): Promise<string> {
    if (gen !== this.gen) return Promise.reject(new LinkError("closed"));
    const queued = this.replies.shift();
    if (queued !== undefined) return Promise.resolve(queued);
    const token = ++this.deadline;
    this.ctx.at(this.ctx.now() + REPLY_TIMEOUT, () => {
      if (token !== this.deadline || gen !== this.gen) return;
      this.fail(gen, `no ${what} within ${REPLY_TIMEOUT} s`);
    });
    return new Promise((resolve, reject) => {
      this.waiting = {
        resolve: (r) => {
          this.deadline++;
          resolve(r);
        },
        reject,
      };
    });
  }

  private async ask(gen: number, command: string): Promise<string> {
    if (gen !== this.gen || !this.cmd) throw new LinkError("closed");
    this.cmd.write(command + TRIGNO_TERMINATOR);
    return this.next(gen, `reply to ${command}`);
  }

  /** A command that must be answered OK; `optional`: another answer is only a warning. */
  private async expectOk(gen: number, command: string, optional = false): Promise<void> {
    const r = await this.ask(gen, command);
    if (r.toUpperCase() === "OK") return;
    if (!optional) throw new Error(`${command} was answered ${quote(r)}, not OK`);
    this.ev.warn(`${this.target} answered ${command} with ${quote(r)}, not OK`);
  }

  private async number(gen: number, command: string): Promise<number | undefined> {
    const r = await this.ask(gen, command);
    const x = Number(r);
    if (r === "" || !Number.isFinite(x) || x <= 0) {
      this.ev.warn(`${this.target} answered ${command} with ${quote(r)}, not a number`);
      return undefined;
    }
    return x;
  }

  /** The whole exchange, from the banner to START. */
  private async session(gen: number): Promise<void> {
    this.counts.banner = await this.next(gen, "banner on the command port");
    await this.expectOk(gen, "BACKWARDS COMPATIBILITY OFF", true);
    await this.expectOk(gen, "UPSAMPLE OFF", true);
    await this.querySensors(gen);
    await this.queryRate(gen);
    await this.queryAux(gen);
    await this.connectData(gen);
    await this.connectAux(gen);
    this.started = true; // data may come before START's reply
    await this.expectOk(gen, "START");
    this.streaming();
  }

  private async querySensors(gen: number): Promise<void> {
    const unpaired: number[] = [];
    for (const s of this.o.sensors) {
      const paired = (await this.ask(gen, `SENSOR ${s} PAIRED?`)).toUpperCase();
      if (paired !== "YES") {
        unpaired.push(s);
        continue;
      }
      this.counts.types[s] = await this.ask(gen, `SENSOR ${s} TYPE?`);
    }
    const before = this.counts.unpaired.join(",");
    this.counts.unpaired = unpaired;
    // Unpaired slots carry zeros: anything else there means a misaligned stream.
    const all = new Set<number>(unpaired);
    this.parser.setUnpaired(all);
    this.auxParser?.setUnpaired(all);
    if (unpaired.length > 0 && unpaired.join(",") !== before) {
      this.ev.warn(
        `${this.target}: sensor${unpaired.length > 1 ? "s" : ""} ${unpaired.join(", ")} not paired: ${unpaired.length > 1 ? "their channels stay" : "its channel stays"} 0 (pair them in the Trigno Control Utility)`,
      );
    }
  }

  private async queryRate(gen: number): Promise<void> {
    const interval = (await this.number(gen, "FRAME INTERVAL?")) ?? TRIGNO_FRAME_INTERVAL;
    const samples = await this.number(gen, "MAX SAMPLES EMG?");
    const rate = samples !== undefined ? samples / interval : TRIGNO_NATIVE_RATE;
    const changed = !this.everStreamed || Math.abs(rate - this.counts.rate) > 1e-6 * rate;
    if (changed && Math.abs(rate - TRIGNO_NATIVE_RATE) > 1e-3) {
      this.ev.warn(
        `${this.target} streams EMG at ${hzText(rate)} (${samples} samples per ${interval * 1000} ms), not the native ${hzText(TRIGNO_NATIVE_RATE)}: samples are stamped at ${hzText(rate)}`,
      );
    }
    this.counts.rate = rate;
  }

  /** The AUX samples per frame (when the AUX port is used); the join starts again. */
  private async queryAux(gen: number): Promise<void> {
    if (!this.join) return;
    const auxPerFrame = (await this.number(gen, "MAX SAMPLES AUX?")) ?? TRIGNO_AUX_SAMPLES;
    const emgPerFrame = Math.round(this.counts.rate * TRIGNO_FRAME_INTERVAL);
    this.counts.aux.perFrame = auxPerFrame;
    this.join.restart(emgPerFrame, auxPerFrame);
  }

  private connectData(gen: number): Promise<void> {
    return this.connectPort(
      gen,
      "EMG",
      this.o.emgPort,
      (d) => this.onData(gen, d),
      (h) => {
        this.data = h;
      },
    );
  }

  private async connectAux(gen: number): Promise<void> {
    if (!this.join) return;
    const port = this.o.auxPort ?? TRIGNO_AUX_PORT;
    await this.connectPort(
      gen,
      "AUX",
      port,
      (d) => this.onAuxData(gen, d),
      (h) => {
        this.auxSock = h;
      },
    );
  }

  /**
   * Connects a data port (`keep` gets the handle at once, so a teardown meanwhile closes it);
   * resolves once connected, fails the link if it ends later.
   */
  private connectPort(
    gen: number,
    what: string,
    port: number,
    onData: (d: Uint8Array) => void,
    keep: (h: TcpSocketHandle) => void,
  ): Promise<void> {
    return new Promise((resolve, reject) => {
      const h = this.tcp.connect(
        { host: this.o.host, port },
        {
          onConnect: () => {
            if (gen === this.gen) resolve();
          },
          onData,
          onClose: (reason, wasOpen) => {
            const why = wasOpen
              ? `the ${what} data connection (port ${port}) ended: ${reason}`
              : `${what} data port: ${reason}`;
            if (!wasOpen) reject(new Error(why));
            else this.fail(gen, why);
          },
        },
        { timeoutMs: REPLY_TIMEOUT * 1000 },
      );
      keep(h);
    });
  }

  private streaming(): void {
    const reconnected = this.everStreamed;
    if (reconnected) this.counts.reconnections++;
    this.everStreamed = true;
    const attempts = this.counts.failures;
    this.counts.failures = 0;
    const n = this.o.sensors.length;
    const aux = this.o.aux ?? 0;
    const withAux = aux === 0 ? "" : ` with ${aux === 3 ? "accelerometers" : "IMUs"} (AUX)`;
    this.ev.state(
      "streaming",
      `streaming ${n} sensor${n === 1 ? "" : "s"}${withAux} at ${hzText(this.counts.rate)} from ${this.target}`,
    );
    if (reconnected) {
      this.ev.warn(
        `reconnected to ${this.target} after ${attempts} failed attempt${attempts === 1 ? "" : "s"}; streaming again`,
      );
    }
    this.ev.started?.(this.counts.rate, reconnected);
  }
}

/** The protocol module of the timer-paced form: every sample goes to the paced device's queue. */
export function delsysProtocol(
  o: TrignoLinkOptions,
  onLink?: (link: TrignoLink) => void,
): DeviceProtocol {
  return {
    open(ctx: BlockContext, sink: DeviceSampleSink) {
      const tcp = ctx.io.tcp;
      const target = `the Trigno Control Utility at ${o.host}:${o.commandPort}`;
      if (!tcp) {
        sink.state("lost", "TCP not available in the browser build; use --simulate-devices");
        sink.warn(noTcpMessage(target));
        return undefined;
      }
      const k = trignoWidth(o);
      const link = new TrignoLink(ctx, tcp, o, {
        samples(values, n) {
          for (let i = 0; i < n; i++) sink.push(values, i * k);
        },
        state: (phase, text) => sink.state(phase, text),
        warn: (m) => sink.warn(m),
      });
      onLink?.(link);
      link.open();
      return { close: () => link.close() };
    },
  };
}
