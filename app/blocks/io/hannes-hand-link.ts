/**
 * The HannesHand block's link to the hand: the Rehab Dongle's serial port and the original's
 * connection sequence (command mode, scan, connect, EnterCMDMode ACK, configure, stream) and
 * disconnection (the behaviour is described in the block's help, hannes-hand.ts).
 */
import type { BlockContext, SerialHandle, SerialStatus } from "../../engine";
import {
  ACK_LINE,
  ascii,
  CMD,
  DEFAULT_JOINT_MASK,
  DONGLE,
  LineSplitter,
  NACK_LINE,
  NEUTRAL_REFERENCE,
  packet,
  parseScanLine,
  REF,
  simultRefPayload,
  SUCCESS_LINE,
  UNITY_CONTROL,
  type ScannedDevice,
} from "./hannes-protocol";

/** The original's waits (HannesHand.cs), seconds. */
const WAIT = {
  /** After opening the port and after "$$$". */
  dongle: 0.5,
  /** For the scan table. */
  scan: 1.5,
  /** After "con N". */
  connect: 0.5,
  /** For the ACK of EnterCMDMode. */
  ping: 1,
  /** After configuring, before streaming. */
  configure: 1,
  /** Between "$$$" and "dct" when disconnecting. */
  disconnect: 2,
};
export const MAX_SCANS = 3;

export type Phase =
  | "unavailable"
  | "closed"
  | "waiting"
  | "opening"
  | "dongle"
  | "scanning"
  | "connecting"
  | "pinging"
  | "configuring"
  | "streaming"
  | "failed";

/** What the block's params say about the link. */
export interface HannesLinkOptions {
  port: string;
  /** Seconds between attempts to reopen the port (0: never). */
  reconnect: number;
  /** Connect when the port opens. */
  connect: boolean;
  /** The Hannes to connect to, by name; undefined: the first found. */
  device: string | undefined;
}

export class HannesLink {
  phase: Phase = "closed";
  /** Why the port does not open, or why the connection failed. */
  detail = "";
  handle: SerialHandle | undefined;
  portOpen = false;
  wantConnect: boolean;
  wanted: string | undefined;
  /** The devices the scans found. */
  readonly devices: ScannedDevice[] = [];
  device: ScannedDevice | undefined;
  /** The scan attempt, 1 to MAX_SCANS. */
  attempt = 0;
  nacks = 0;
  /** Lines received since the last step began. */
  private received: string[] = [];
  private readonly lines = new LineSplitter();
  /** Each step that waits gets a number; a wait that is overtaken does nothing. */
  private gen = 0;

  constructor(
    private readonly ctx: BlockContext,
    private readonly o: HannesLinkOptions,
    /** The phase, the device or the counts changed. */
    private readonly changed: () => void,
  ) {
    this.wantConnect = o.connect;
    this.wanted = o.device;
  }

  /** Opens the port (it connects to the hand when it opens, if wanted). */
  open(): void {
    const bridge = this.ctx.io.serial;
    if (!bridge) {
      this.phase = "unavailable";
      this.ctx.warn(
        "serial ports are not available here (browser build): the Hannes hand gets nothing",
      );
      this.changed();
      return;
    }
    if (this.handle) return;
    this.phase = "opening";
    this.detail = "";
    this.handle = bridge.open({
      path: this.o.port,
      baudRate: 115200,
      dataBits: 8,
      stopBits: 1,
      parity: "none",
      reconnectMs: this.o.reconnect * 1000,
      onData: (b) => this.lines.push(b, this.onLine),
      onStatus: (s, msg) => this.onStatus(s, msg),
    });
    this.changed();
  }

  /** Sends one reference while streaming; true when it was sent. */
  sendReference(ref: Float64Array): boolean {
    if (this.phase !== "streaming" || !this.handle) return false;
    this.handle.write(packet(simultRefPayload(ref)));
    return true;
  }

  /** The dongle in command mode, then the scans. */
  begin(): void {
    this.attempt = 0;
    this.device = undefined;
    this.phase = "dongle";
    this.after(WAIT.dongle, () => {
      this.write(ascii(DONGLE.commandMode));
      this.after(WAIT.dongle, () => this.scan());
    });
    this.changed();
  }

  /**
   * The original's disconnect: neutral pose, the hand back to command mode, then "$$$" and the
   * dongle's "dct" 2 s later (`wait`: the pipeline runs, so the wait is a timer; at stop both go
   * at once, and the port closes).
   */
  disconnect(wait: boolean): void {
    this.gen++;
    const h = this.handle;
    if (!h) return;
    if (this.phase === "streaming" || this.phase === "configuring") {
      h.write(packet(simultRefPayload(NEUTRAL_REFERENCE)));
      h.write(packet([CMD.EnterCMDMode]));
    }
    h.write(ascii(DONGLE.commandMode));
    const finish = (): void => {
      h.write(ascii(DONGLE.disconnect));
      h.close();
    };
    this.handle = undefined;
    this.portOpen = false;
    if (wait) {
      // Not through `after`: a reconnect in the meantime must not cancel it.
      this.ctx.at(this.ctx.now() + WAIT.disconnect, finish);
    } else finish();
    this.phase = "closed";
    this.device = undefined;
    this.changed();
  }

  /** Closes the port at once. */
  close(): void {
    this.gen++;
    this.handle?.close();
    this.handle = undefined;
  }

  private write(b: Uint8Array): void {
    this.handle?.write(b);
  }

  /** Runs `fn` after `seconds`, unless something else happened in between. */
  private after(seconds: number, fn: () => void): void {
    const g = ++this.gen;
    this.ctx.at(this.ctx.now() + seconds, () => {
      if (g === this.gen) fn();
    });
  }

  private fail(why: string): void {
    this.gen++;
    this.phase = "failed";
    this.detail = why;
    this.ctx.warn(`${this.o.port}: ${why}`);
    this.changed();
  }

  private scan(): void {
    this.attempt++;
    this.received = [];
    this.phase = "scanning";
    this.changed();
    this.after(WAIT.scan, () => this.scanned());
    this.write(ascii(DONGLE.scan));
  }

  /** The scan's wait is over: scan again, fail, or connect to the device found. */
  private scanned(): void {
    if (!this.received.includes(SUCCESS_LINE)) {
      if (this.attempt < MAX_SCANS) this.scan();
      else
        this.fail("the dongle did not answer the scan: is it plugged in? Unplug and reconnect it");
      return;
    }
    const devices = this.devices;
    for (const l of this.received) {
      const d = parseScanLine(l);
      if (d && !devices.some((x) => x.address === d.address)) devices.push(d);
    }
    if (devices.length === 0) {
      this.fail("no Hannes found by the scan: is the hand switched on?");
      return;
    }
    const wanted = this.wanted;
    const d = wanted === undefined ? devices[0] : devices.find((x) => x.name === wanted);
    if (!d) {
      this.fail(`'${wanted}' not found; the scan found ${devices.map((x) => x.name).join(", ")}`);
      return;
    }
    this.connectTo(d);
  }

  private connectTo(d: ScannedDevice): void {
    this.device = d;
    this.phase = "connecting";
    this.write(ascii(DONGLE.connect(d.con)));
    this.changed();
    this.after(WAIT.connect, () => this.ping(d));
  }

  /** Asks the hand for the ACK of EnterCMDMode (configure follows when it comes). */
  private ping(d: ScannedDevice): void {
    this.received = [];
    this.phase = "pinging";
    this.changed();
    // The timeout first: the ACK (which moves on) may arrive while the packet is written.
    this.after(WAIT.ping, () =>
      this.fail(
        `${d.name} did not acknowledge (no ACK to EnterCMDMode within ${WAIT.ping} s): is it on and in range?`,
      ),
    );
    this.write(packet([CMD.EnterCMDMode]));
  }

  private configure(): void {
    this.phase = "configuring";
    this.write(packet([CMD.RefControl, REF.JOINT_SET, DEFAULT_JOINT_MASK]));
    this.write(packet([CMD.RefControl, REF.CONTROL_MODE, UNITY_CONTROL]));
    this.write(packet([CMD.ExitCMDMode]));
    this.changed();
    this.after(WAIT.configure, () => {
      this.phase = "streaming";
      this.changed();
    });
  }

  private readonly onLine = (line: string): void => {
    const received = this.received;
    received.push(line);
    if (received.length > 1000) received.shift();
    if (line === NACK_LINE) {
      this.nacks++;
      this.changed();
    } else if (this.phase === "pinging" && line === ACK_LINE) {
      this.configure();
    }
  };

  private onStatus(s: SerialStatus, msg?: string): void {
    if (s === "open") {
      this.portOpen = true;
      this.lines.reset();
      if (this.wantConnect) this.begin();
      else {
        this.phase = "waiting";
        this.changed();
      }
      return;
    }
    const was = this.portOpen;
    this.portOpen = false;
    this.gen++;
    if (s === "error") {
      const news = was || this.phase !== "opening" || this.detail !== (msg ?? "");
      this.phase = "opening";
      this.detail = msg ?? "";
      if (news) this.ctx.warn(`${this.o.port}: ${msg ?? "error"}`);
    } else if (s === "closed") {
      this.phase = "closed";
    }
    this.changed();
  }
}
