/**
 * One Myo block at run time: follows the Bluetooth adapter, scans for an armband (claiming it so
 * that no other Myo block of the worker takes it), connects and sets it up, decodes its EMG and
 * IMU notifications into events (or queues the EMG samples for a timer input), searches again
 * after a lost link, and says the link's state and counts in the status (the behaviour is
 * described in the block's help, myo.ts).
 */
import type {
  BleAdapterState,
  BleBridge,
  BleConnection,
  BlePeripheral,
  BlockContext,
  BlockInstance,
  Frame,
  OutputPort,
} from "../../engine";
import { ADAPTER_TEXT, addressKey, claimsOf, connectAttempt, errorText } from "../shared/ble";
import { plural, TextThrottle } from "../shared/text";
import {
  decodeEmg,
  decodeImu,
  EMG_CHANNELS,
  EmgTimestamps,
  IMU_VALUES,
  MYO,
  normalizeUuid,
  sameAddress,
  setModeCommand,
  SLEEP_MODE,
  sleepModeCommand,
  VIBRATION,
  vibrateCommand,
} from "./myo-protocol";

/** What the block's params decide (the Myo block's params, as they are). */
export interface MyoSettings {
  Address?: string | undefined;
  IMU: boolean;
  Vibrate: boolean;
  Reconnect: number;
  MaxDelay: number;
}

type Phase =
  | "unavailable"
  | "adapter"
  | "scanning"
  | "connecting"
  | "configuring"
  | "streaming"
  | "lost"
  | "stopped";

/** "service/characteristic" keys of what a connection's discovery found. */
function characteristicKeys(found: readonly { service: string; uuid: string }[]): Set<string> {
  return new Set(found.map((x) => `${normalizeUuid(x.service)}/${normalizeUuid(x.uuid)}`));
}

/** The first characteristic the block needs that `found` lacks, if any. */
function missingCharacteristic(found: Set<string>, imu: boolean): string | undefined {
  const need: [string, string][] = [
    [MYO.controlService, MYO.commandCharacteristic],
    ...MYO.emgCharacteristics.map((u): [string, string] => [MYO.emgService, u]),
    ...(imu ? [[MYO.imuService, MYO.imuCharacteristic] as [string, string]] : []),
  ];
  const missing = need.filter(([s, u]) => !found.has(`${s}/${u}`));
  return missing.length > 0 ? missing[0]![1] : undefined;
}

/** MOSAIC's end commands: stop streaming, let the armband sleep again; then disconnect. */
function endSession(c: BleConnection): void {
  const writes = [
    c.write(MYO.controlService, MYO.commandCharacteristic, setModeCommand(0, 0, 0)),
    c.write(MYO.controlService, MYO.commandCharacteristic, sleepModeCommand(SLEEP_MODE.normal)),
  ];
  void Promise.allSettled(writes).then(() => c.disconnect());
}

export class MyoRun {
  private readonly scratch = new Float64Array(2 * EMG_CHANNELS);
  private readonly imuScratch = new Float64Array(IMU_VALUES);
  private readonly stamps = new Float64Array(2);
  private readonly clock = new EmgTimestamps();
  /** Timer mode: a FIFO of EMG samples (MaxDelay × 8) and the sample held between them. */
  private readonly queue: Float64Array;
  private qHead = 0;
  private qLen = 0;
  private readonly held = new Float64Array(EMG_CHANNELS);

  private bridge: BleBridge | undefined;
  private watch: { close(): void } | undefined;
  private scan: { stop(): void } | undefined;
  private conn: BleConnection | undefined;
  private address: string | undefined;
  /** Bumped when an attempt or a link is abandoned: callbacks of older ones do nothing. */
  private gen = 0;
  private phase: Phase = "stopped";
  private adapter: BleAdapterState = "unknown";
  private adapterMessage = "";
  private problem = "";
  private emgSamples = 0;
  private imuSamples = 0;
  private malformed = 0;
  private lastMalformed = "";
  private dropped = 0;
  private disconnections = 0;
  private readonly throttle = new TextThrottle(0.5);
  private lastText = "";

  constructor(
    private readonly ctx: BlockContext,
    private readonly p: MyoSettings,
    /** A timer input paces the EMG output (MOSAIC's form). */
    private readonly paced: boolean,
    /** The set-mode command that starts streaming. */
    private readonly modeCommand: Uint8Array,
    private readonly emgOut: OutputPort,
    private readonly imuOut: OutputPort,
  ) {
    this.queue = new Float64Array(paced ? p.MaxDelay * EMG_CHANNELS : 0);
  }

  instance(): BlockInstance {
    return {
      start: () => this.start(),
      stop: () => this.stop(),
      process: (frame: Frame) => this.process(frame),
      reset: () => this.reset(),
      dispose: () => this.dispose(),
      actions: {
        vibrate: {
          label: "Vibrate",
          description: "Makes the armband vibrate briefly (to find which one is which)",
          run: () => this.vibrate(),
        },
      },
    };
  }

  private name(): string {
    return this.address ?? this.p.Address ?? "a Myo";
  }

  // ---- status ----

  private phaseText(): string {
    const p = this.p;
    switch (this.phase) {
      case "unavailable":
        return "Bluetooth LE is not available here (browser build): run the pipeline with mosaic run or the desktop app";
      case "adapter":
        return this.adapter === "poweredOn"
          ? "Bluetooth adapter on"
          : this.adapterMessage !== ""
            ? this.adapterMessage
            : ADAPTER_TEXT[this.adapter];
      case "scanning":
        return `searching for ${p.Address ?? "a Myo armband"}…`;
      case "connecting":
        return `connecting to ${this.name()}…`;
      case "configuring":
        return `setting up ${this.name()}…`;
      case "streaming": {
        const text = `${this.name()} streaming · ${plural(this.emgSamples, "EMG sample")}`;
        return p.IMU ? `${text} · ${this.imuSamples} IMU` : text;
      }
      case "lost":
        return (
          `${this.name()}: ${this.problem}; ` +
          (p.Reconnect > 0
            ? `searching again in ${p.Reconnect} s`
            : "not reconnecting (Reconnect 0)")
        );
      case "stopped":
        return this.address ? `${this.address} disconnected` : "stopped";
    }
  }

  /** Shows the phase and the counts in the status, when they changed. */
  private refresh(): void {
    let text = this.phaseText();
    if (this.disconnections > 0) text += ` · ${plural(this.disconnections, "disconnection")}`;
    if (this.dropped > 0) text += ` · ${this.dropped} EMG samples dropped (MaxDelay)`;
    if (this.malformed > 0) text += ` · ${this.malformed} malformed (last: ${this.lastMalformed})`;
    if (text !== this.lastText) {
      this.lastText = text;
      this.ctx.setText(text);
    }
  }

  // ---- adapter, scan, link ----

  private release(): void {
    if (this.bridge && this.address) claimsOf(this.bridge).delete(addressKey(this.address));
  }

  private stopScan(): void {
    this.scan?.stop();
    this.scan = undefined;
  }

  private unwatch(): void {
    this.watch?.close();
    this.watch = undefined;
  }

  /** Drops the link (if any) and this block's claim on the armband. */
  private dropLink(): void {
    this.conn?.disconnect();
    this.conn = undefined;
    this.release();
  }

  private readonly onState = (s: BleAdapterState, message?: string): void => {
    this.adapter = s;
    this.adapterMessage = message ?? "";
    if (s === "poweredOn") {
      if (this.phase === "adapter" || this.phase === "stopped") this.beginScan();
      else this.refresh();
      return;
    }
    // The adapter went away: the link (if any) is gone with it.
    this.gen++;
    this.stopScan();
    this.dropLink();
    this.phase = "adapter";
    this.refresh();
  };

  private beginScan(): void {
    const bridge = this.bridge;
    if (!bridge || this.scan || this.conn) return;
    if (this.phase === "connecting" || this.phase === "configuring") return;
    if (this.adapter !== "poweredOn") return;
    this.phase = "scanning";
    this.refresh();
    const g = this.gen;
    const handle = bridge.scan({
      services: [MYO.controlService],
      onFound: this.onFound,
      onError: (m) => {
        if (g === this.gen) this.fail(m);
      },
    });
    // An error reported (or an armband found) before `scan` returned has moved on already.
    if (g === this.gen && this.phase === "scanning") this.scan = handle;
    else handle.stop();
  }

  private retryLater(): void {
    if (this.p.Reconnect <= 0) return;
    const g = this.gen;
    this.ctx.at(this.ctx.now() + this.p.Reconnect, () => {
      if (g !== this.gen || this.phase !== "lost") return;
      this.beginScan();
    });
  }

  /** The attempt (or the link) failed: say why, clean up, search again later. */
  private fail(reason: string): void {
    this.gen++;
    this.stopScan();
    this.dropLink();
    this.problem = reason;
    this.phase = "lost";
    this.ctx.warn(`${this.name()}: ${reason}`);
    this.refresh();
    this.retryLater();
  }

  private readonly onFound = (found: BlePeripheral): void => {
    const bridge = this.bridge;
    if (!bridge || this.phase !== "scanning") return;
    if (this.p.Address !== undefined) {
      if (!sameAddress(found.address, this.p.Address)) return;
    } else if (claimsOf(bridge).has(addressKey(found.address))) {
      return;
    }
    this.stopScan();
    void this.connect(bridge, found.address);
  };

  private async connect(b: BleBridge, to: string): Promise<void> {
    const g = ++this.gen;
    this.address = to;
    claimsOf(b).add(addressKey(to));
    this.phase = "connecting";
    this.refresh();
    await connectAttempt(b, to, {
      onLost: (reason) => {
        if (g !== this.gen) return;
        this.conn = undefined;
        this.disconnections++;
        this.fail(`disconnected (${reason})`);
      },
      current: () => g === this.gen,
      fail: (reason) => this.fail(reason),
      connected: async (c) => {
        this.conn = c;
        this.phase = "configuring";
        this.refresh();
        await this.configure(c, g);
      },
    });
  }

  /** Checks the armband's characteristics, subscribes, and starts it streaming. */
  private async configure(c: BleConnection, g: number): Promise<void> {
    try {
      const found = characteristicKeys(
        await c.discover([MYO.controlService, MYO.emgService, MYO.imuService]),
      );
      if (g !== this.gen) return;
      const missing = missingCharacteristic(found, this.p.IMU);
      if (missing !== undefined) {
        this.fail(`not a Myo armband (missing characteristic ${missing})`);
        return;
      }
      const command = (bytes: Uint8Array): Promise<void> =>
        c.write(MYO.controlService, MYO.commandCharacteristic, bytes);
      await command(sleepModeCommand(SLEEP_MODE.neverSleep));
      for (const u of MYO.emgCharacteristics) {
        await c.subscribe(MYO.emgService, u, (d) => {
          if (g === this.gen) this.onEmg(d);
        });
      }
      if (this.p.IMU) {
        await c.subscribe(MYO.imuService, MYO.imuCharacteristic, (d) => {
          if (g === this.gen) this.onImu(d);
        });
      }
      await command(this.modeCommand);
      if (this.p.Vibrate) await command(vibrateCommand(VIBRATION.short));
      if (g !== this.gen) return;
      this.clock.reset();
      this.phase = "streaming";
      this.problem = "";
      this.refresh();
    } catch (e) {
      if (g === this.gen) this.fail(`setting up failed: ${errorText(e)}`);
    }
  }

  // ---- notifications ----

  /** A malformed notification is counted and shown, not thrown. */
  private bad(why: string): void {
    this.malformed++;
    this.lastMalformed = why;
    this.refresh();
  }

  private onEmg(data: Uint8Array): void {
    const err = decodeEmg(data, this.scratch);
    if (err !== undefined) return this.bad(err);
    this.emgSamples += 2;
    const now = this.ctx.now();
    if (this.paced) this.enqueue();
    else this.emitEmg(now);
    if (this.throttle.due(now)) this.refresh();
  }

  /** Emits the two decoded EMG samples, stamped 5 ms apart. */
  private emitEmg(now: number): void {
    this.clock.stamp(now, this.stamps);
    const f = this.emgOut.frame(2);
    f.t[0] = this.stamps[0]!;
    f.t[1] = this.stamps[1]!;
    f.v.set(this.scratch);
    this.emgOut.emit(f);
  }

  /** Timer mode: queues the two decoded EMG samples, dropping the oldest beyond MaxDelay. */
  private enqueue(): void {
    const max = this.p.MaxDelay;
    for (let s = 0; s < 2; s++) {
      if (this.qLen === max) {
        this.qHead = (this.qHead + 1) % max;
        this.qLen--;
        this.dropped++;
      }
      this.queue.set(
        this.scratch.subarray(s * EMG_CHANNELS, (s + 1) * EMG_CHANNELS),
        ((this.qHead + this.qLen) % max) * EMG_CHANNELS,
      );
      this.qLen++;
    }
  }

  private onImu(data: Uint8Array): void {
    const err = decodeImu(data, this.imuScratch);
    if (err !== undefined) return this.bad(err);
    this.imuSamples++;
    const f = this.imuOut.frame(1);
    f.t[0] = this.ctx.now();
    f.v.set(this.imuScratch);
    this.imuOut.emit(f);
  }

  // ---- the block's instance ----

  private start(): void {
    this.bridge = this.ctx.io.ble;
    if (!this.bridge) {
      this.phase = "unavailable";
      this.refresh();
      return;
    }
    this.phase = "adapter";
    this.watch = this.bridge.watchState(this.onState);
  }

  private stop(): void {
    this.gen++;
    this.unwatch();
    this.stopScan();
    const c = this.conn;
    this.conn = undefined;
    this.release();
    if (c) endSession(c);
    if (this.phase !== "unavailable") this.phase = "stopped";
    this.refresh();
  }

  /** Timer mode (MOSAIC): one EMG event per tick. */
  private process(frame: Frame): void {
    const out = this.emgOut.frame(frame.n);
    for (let e = 0; e < frame.n; e++) {
      if (this.phase !== "streaming") {
        this.held.fill(0);
      } else if (this.qLen > 0) {
        this.held.set(
          this.queue.subarray(this.qHead * EMG_CHANNELS, (this.qHead + 1) * EMG_CHANNELS),
        );
        this.qHead = (this.qHead + 1) % this.p.MaxDelay;
        this.qLen--;
      }
      out.t[e] = frame.t[e]!;
      out.v.set(this.held, e * EMG_CHANNELS);
    }
    this.emgOut.emit(out);
  }

  private reset(): void {
    this.qHead = 0;
    this.qLen = 0;
    this.held.fill(0);
    this.clock.reset();
    this.emgSamples = 0;
    this.imuSamples = 0;
    this.malformed = 0;
    this.lastMalformed = "";
    this.dropped = 0;
    this.disconnections = 0;
    this.refresh();
  }

  private dispose(): void {
    this.gen++;
    this.unwatch();
    this.stopScan();
    this.dropLink();
  }

  private vibrate(): string {
    const conn = this.conn;
    if (!conn || this.phase !== "streaming") return `${this.name()} is not connected`;
    void conn
      .write(MYO.controlService, MYO.commandCharacteristic, vibrateCommand(VIBRATION.medium))
      .catch(() => {});
    return `${this.name()} vibrates`;
  }
}
