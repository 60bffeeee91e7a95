/**
 * The NilsPod block's link over the host's Bluetooth LE bridge (`ctx.io.ble`; the original
 * MOSAIC's BluetoothLEManager): wait for the adapter, scan (for `Address`, or the first peripheral
 * whose name begins "NilsPod" that no other NilsPod block of this worker uses), connect, discover
 * the streaming service, subscribe to the sample characteristic, write the start command, decode
 * every notification into the paced device's queue (nilspod-protocol.ts). Counts: samples, samples
 * lost (the counter's gaps), counter restarts, malformed notifications (counted, warned, never
 * thrown), disconnections and reconnections. A lost link, a failed connection or 2 s without a
 * sample is reported and the search starts again after 0.5 s, 1 s, 2 s, 4 s, then every 5 s (the
 * device links' policy, stream-link.ts). Closing writes the stop command, then disconnects.
 *
 * One heartbeat (`ctx.at`, every 0.1 s) looks at every deadline: the retry, the silence, and the
 * scan's restart every 5 s while nothing matched (a bridge reports a peripheral once per scan, and
 * the first report may come before its name, which arrives in the scan response).
 */
import type {
  BleAdapterState,
  BleBridge,
  BleConnection,
  BlePeripheral,
  BlockContext,
} from "../../engine";
import { ADAPTER_TEXT, addressKey, claimsOf, connectAttempt, errorText } from "../shared/ble";
import { plural } from "../shared/text";
import {
  decodeNilsPod,
  NILSPOD,
  NILSPOD_COMMAND,
  NILSPOD_NAME_PREFIX,
  NILSPOD_VALUES,
  NilsPodCounter,
  nilsPodScales,
  nilsPodTarget,
  type NilsPodScales,
} from "./nilspod-protocol";
import type { DeviceProtocol, DeviceSampleSink } from "./paced-device";
import { retryWait } from "./stream-link";

/** Seconds without a sample after which a streaming link counts as lost. */
export const NILSPOD_SILENCE = 2;
/** Seconds a scan runs without a match before it is started again. */
export const NILSPOD_SCAN_RESTART = 5;
const HEARTBEAT = 0.1;

type Phase = "adapter" | "scanning" | "connecting" | "configuring" | "streaming" | "lost";

export interface NilsPodCounts {
  samples: number;
  lost: number;
  restarts: number;
  malformed: number;
  lastMalformed: string;
  disconnections: number;
  reconnections: number;
}

export interface NilsPodLinkOptions {
  address: string | undefined;
  scales: NilsPodScales;
  /** "the NilsPod aa:bb:… over Bluetooth LE", for messages. */
  target: string;
}

/** One block's link to one NilsPod (see the file comment). */
export class NilsPodLink {
  readonly counts: NilsPodCounts = {
    samples: 0,
    lost: 0,
    restarts: 0,
    malformed: 0,
    lastMalformed: "",
    disconnections: 0,
    reconnections: 0,
  };
  private gen = 0;
  private closed = true;
  private phase: Phase = "adapter";
  private adapter: BleAdapterState = "unknown";
  private adapterMessage = "";
  private warnedAdapter = false;
  private watch: { close(): void } | undefined;
  private scan: { stop(): void } | undefined;
  private scanSince = 0;
  private conn: BleConnection | undefined;
  /** The peripheral connected to (or being connected to), and its advertised name. */
  private address: string | undefined;
  private name = "";
  private problem = "";
  private failures = 0;
  private retryAt = -1;
  private lastData = 0;
  private everStreamed = false;
  private shownExtras = "";
  /** The command characteristic takes writes with response (else without). */
  private withResponse = true;
  private readonly counter = new NilsPodCounter();
  private readonly values = new Float64Array(NILSPOD_VALUES);

  constructor(
    private readonly ctx: BlockContext,
    private readonly bridge: BleBridge,
    private readonly sink: DeviceSampleSink,
    private readonly o: NilsPodLinkOptions,
  ) {}

  open(): void {
    if (!this.closed) return;
    this.closed = false;
    this.phase = "adapter";
    this.watch = this.bridge.watchState((s, m) => this.onState(s, m));
    this.heartbeat();
  }

  /** Stops: the stop command (when connected), then disconnect. */
  close(): void {
    if (this.closed) return;
    this.closed = true;
    this.gen++;
    this.watch?.close();
    this.watch = undefined;
    this.stopScan();
    const c = this.conn;
    this.conn = undefined;
    this.release();
    if (c) {
      void this.command(c, NILSPOD_COMMAND.stopStreaming)
        .catch(() => {})
        .then(() => c.disconnect());
    }
  }

  private onState(s: BleAdapterState, message?: string): void {
    if (this.closed) return;
    this.adapter = s;
    this.adapterMessage = message ?? "";
    if (s === "poweredOn") {
      if (this.phase === "adapter") this.beginScan();
      return;
    }
    if (s !== "unknown" && s !== "resetting" && !this.warnedAdapter) {
      this.warnedAdapter = true;
      this.sink.warn(
        `${this.adapterMessage || ADAPTER_TEXT[s]}: ${this.o.target} cannot be reached, the block ` +
          "sends zeros (without the device: mosaic run --simulate-devices)",
      );
    }
    // The adapter went away: the link (if any) went with it.
    if (this.phase === "streaming") this.counts.disconnections++;
    this.drop();
    this.phase = "adapter";
    this.retryAt = -1;
    this.describe();
  }

  private heartbeat(): void {
    if (this.closed) return;
    const now = this.ctx.now();
    if (this.retryAt >= 0 && now >= this.retryAt) {
      this.retryAt = -1;
      this.beginScan();
    } else if (this.phase === "scanning" && now - this.scanSince >= NILSPOD_SCAN_RESTART) {
      this.stopScan();
      this.beginScan();
    } else if (this.phase === "streaming" && now - this.lastData > NILSPOD_SILENCE) {
      this.counts.disconnections++;
      this.fail(`no data for ${NILSPOD_SILENCE} s`);
    }
    this.ctx.at(now + HEARTBEAT, () => this.heartbeat());
  }

  private beginScan(): void {
    if (this.closed || this.scan || this.conn) return;
    if (this.adapter !== "poweredOn") {
      this.phase = "adapter";
      this.describe();
      return;
    }
    this.phase = "scanning";
    this.scanSince = this.ctx.now();
    this.describe();
    const g = this.gen;
    const handle = this.bridge.scan({
      services: [],
      onFound: (p) => {
        if (g === this.gen) this.onFound(p);
      },
      onError: (m) => {
        if (g === this.gen) this.fail(m);
      },
    });
    // Something reported before `scan` returned (a match, an error) has moved on already.
    if (g === this.gen && this.phase === "scanning") this.scan = handle;
    else handle.stop();
  }

  private stopScan(): void {
    this.scan?.stop();
    this.scan = undefined;
  }

  private wanted(p: BlePeripheral): boolean {
    if (this.o.address !== undefined) return addressKey(p.address) === addressKey(this.o.address);
    if (!(p.name ?? "").startsWith(NILSPOD_NAME_PREFIX)) return false;
    return !claimsOf(this.bridge).has(addressKey(p.address));
  }

  private onFound(p: BlePeripheral): void {
    if (this.closed || this.phase !== "scanning" || !this.wanted(p)) return;
    this.stopScan();
    void this.connect(p);
  }

  private async connect(p: BlePeripheral): Promise<void> {
    const g = ++this.gen;
    this.address = p.address;
    this.name = p.name ?? "";
    claimsOf(this.bridge).add(addressKey(p.address));
    this.phase = "connecting";
    this.describe();
    await connectAttempt(this.bridge, p.address, {
      onLost: (reason) => this.onLost(g, reason),
      current: () => g === this.gen,
      fail: (reason) => this.fail(reason),
      connected: async (c) => {
        this.conn = c;
        this.phase = "configuring";
        this.describe();
        try {
          await this.setUp(c, g);
        } catch (e) {
          if (g === this.gen) this.fail(`setting up failed: ${errorText(e)}`);
        }
      },
    });
  }

  /** Discover, subscribe to the samples, then start streaming (the original's order). */
  private async setUp(c: BleConnection, g: number): Promise<void> {
    const found = await c.discover([NILSPOD.service]);
    if (g !== this.gen) return;
    const of = (u: string) =>
      found.find((x) => norm(x.service) === NILSPOD.service && norm(x.uuid) === u);
    const data = of(NILSPOD.data);
    const commands = of(NILSPOD.commands);
    if (!data || !commands) {
      const missing = !data ? NILSPOD.data : NILSPOD.commands;
      this.fail(`not a NilsPod (no characteristic ${missing} in service ${NILSPOD.service})`);
      return;
    }
    this.withResponse = commands.properties.includes("write");
    this.counter.resync();
    await c.subscribe(NILSPOD.service, NILSPOD.data, (d) => {
      if (g === this.gen) this.onData(d);
    });
    if (g !== this.gen) return;
    await this.command(c, NILSPOD_COMMAND.startStreaming);
    if (g !== this.gen) return;
    this.phase = "streaming";
    this.lastData = this.ctx.now();
    this.problem = "";
    if (this.everStreamed) {
      this.counts.reconnections++;
      this.sink.warn(`reconnected to ${this.who()}; streaming again`);
    }
    this.everStreamed = true;
    this.failures = 0;
    this.describe();
  }

  /** Writes with response where the characteristic allows it (the original did), else without. */
  private command(c: BleConnection, byte: number): Promise<void> {
    return c.write(NILSPOD.service, NILSPOD.commands, Uint8Array.of(byte), !this.withResponse);
  }

  private onData(d: Uint8Array): void {
    if (this.closed) return;
    this.lastData = this.ctx.now();
    const err = decodeNilsPod(d, this.o.scales, this.values, (v, counter) => {
      this.counter.next(counter);
      this.counts.samples++;
      this.sink.push(v);
    });
    const c = this.counts;
    c.lost = this.counter.lost;
    c.restarts = this.counter.restarts;
    if (err !== undefined) {
      c.malformed++;
      c.lastMalformed = err;
      this.sink.warn(`malformed notification from ${this.who()} (${err}): dropped`);
    }
    if (this.phase === "streaming" && this.extras() !== this.shownExtras) this.describe();
  }

  private onLost(g: number, reason: string): void {
    if (g !== this.gen || this.closed) return;
    this.conn = undefined;
    this.counts.disconnections++;
    this.fail(`disconnected (${reason})`);
  }

  /** The attempt (or the link) failed: say why, clean up, search again after the backoff. */
  private fail(reason: string): void {
    if (this.closed) return;
    const wasStreaming = this.phase === "streaming";
    this.drop();
    this.failures++;
    this.problem = reason;
    this.phase = "lost";
    const wait = retryWait(this.failures);
    this.retryAt = this.ctx.now() + wait;
    if (wasStreaming) this.sink.warn(`lost ${this.who()}: ${reason}; reconnecting`);
    else if (this.failures === 1) this.sink.warn(`${this.who()}: ${reason}`);
    this.describe();
  }

  /** Ends the connection attempt or link (no stop command: the device is gone or refused). */
  private drop(): void {
    this.gen++;
    this.stopScan();
    this.conn?.disconnect();
    this.conn = undefined;
    this.release();
  }

  private release(): void {
    if (this.address !== undefined) claimsOf(this.bridge).delete(addressKey(this.address));
  }

  private who(): string {
    if (this.address === undefined) return this.o.target.replace(/ over Bluetooth LE$/, "");
    return this.name !== "" ? `${this.name} (${this.address})` : this.address;
  }

  /** " · 3 samples lost · …": the counts worth seeing beside the phase. */
  private extras(): string {
    const c = this.counts;
    let t = "";
    if (c.lost > 0) t += ` · ${plural(c.lost, "sample")} lost (counter gaps)`;
    if (c.restarts > 0) t += ` · counter restarted ${c.restarts}×`;
    if (c.malformed > 0) {
      t += ` · ${plural(c.malformed, "malformed notification")} (last: ${c.lastMalformed})`;
    }
    if (c.disconnections > 0) t += ` · ${plural(c.disconnections, "disconnection")}`;
    if (c.reconnections > 0) t += ` · reconnected ${c.reconnections}×`;
    return t;
  }

  private describe(): void {
    const extras = (this.shownExtras = this.extras());
    switch (this.phase) {
      case "adapter": {
        const text =
          this.adapter === "poweredOn"
            ? "Bluetooth adapter on"
            : this.adapterMessage !== ""
              ? this.adapterMessage
              : ADAPTER_TEXT[this.adapter];
        this.sink.state("connecting", `${text} (sending zeros)${extras}`);
        return;
      }
      case "scanning":
        this.sink.state(
          "connecting",
          `searching for ${this.o.address !== undefined ? `the NilsPod ${this.o.address}` : "a NilsPod"}…${extras}`,
        );
        return;
      case "connecting":
        this.sink.state("connecting", `connecting to ${this.who()}…${extras}`);
        return;
      case "configuring":
        this.sink.state("connecting", `setting up ${this.who()}…${extras}`);
        return;
      case "streaming":
        this.sink.state("streaming", `streaming from ${this.who()}${extras}`);
        return;
      case "lost": {
        const wait = retryWait(this.failures);
        this.sink.state(
          "lost",
          `${this.who()}: ${this.problem}; searching again in ${wait} s (attempt ${this.failures + 1})${extras}`,
        );
        return;
      }
    }
  }
}

const norm = (u: string): string => u.replace(/-/g, "").toLowerCase();

export interface NilsPodLinkParams {
  Address?: string | undefined;
  AccRange?: number | undefined;
  GyroRange?: number | undefined;
}

/** The NilsPod block's protocol module: a `NilsPodLink` over the host's BLE bridge. */
export function nilsPodProtocol(p: NilsPodLinkParams): DeviceProtocol {
  return {
    open(ctx, sink) {
      const bridge = ctx.io.ble;
      const target = nilsPodTarget(p.Address);
      if (!bridge) {
        sink.state(
          "lost",
          "Bluetooth LE is not available here (browser build): run the pipeline with mosaic run or the desktop app; sending zeros",
        );
        sink.warn(
          `Bluetooth LE is not available here (browser build), so ${target} is not reachable: run ` +
            "the pipeline with mosaic run or the desktop app, or with --simulate-devices (the block sends zeros)",
        );
        return undefined;
      }
      const link = new NilsPodLink(ctx, bridge, sink, {
        address: p.Address,
        scales: nilsPodScales(p.AccRange, p.GyroRange),
        target,
      });
      link.open();
      return { close: () => link.close() };
    },
  };
}
