/**
 * One HannesHand block at run time: turns every control event into the hand's four references,
 * emits them and sends them while the link streams; says each step of the link in the status
 * (the behaviour is described in the block's help, hannes-hand.ts).
 */
import type { BlockContext, BlockInstance, Frame, OutputPort } from "../../engine";
import { ACTUATION_SIZE, toActuation, type ControlKind } from "../control/actuation";
import { plural, TextThrottle } from "../shared/text";
import { HannesLink, MAX_SCANS, type HannesLinkOptions } from "./hannes-hand-link";
import { handReference } from "./hannes-protocol";

export class HannesHandRun {
  private readonly link: HannesLink;
  private readonly act = new Float64Array(ACTUATION_SIZE);
  private readonly ref = new Float64Array(4);
  private readonly throttle = new TextThrottle();
  private readonly port: string;
  private started = false;
  private sent = 0;

  constructor(
    private readonly ctx: BlockContext,
    private readonly control: { kind: ControlKind | undefined; size: number },
    /** What the control input is read as, for the status. */
    private readonly reads: string,
    private readonly out: OutputPort,
    o: HannesLinkOptions,
  ) {
    this.port = o.port;
    this.link = new HannesLink(ctx, o, () => this.describe());
    this.describe();
  }

  instance(): BlockInstance {
    const link = this.link;
    return {
      start: () => {
        this.started = true;
        link.open();
      },
      stop: () => {
        this.started = false;
        link.disconnect(false);
      },
      process: (f: Frame) => this.process(f),
      reset: () => {
        this.sent = 0;
        link.nacks = 0;
        this.throttle.reset();
        this.describe();
      },
      dispose: () => link.close(),
      actions: {
        connect: {
          label: "Connect",
          description:
            "Scan and connect to a Hannes (a name, or the Device param / the first found)",
          run: (arg) => this.connect(arg),
        },
        disconnect: {
          label: "Disconnect",
          description: "Neutral pose, then disconnect the hand (the port closes)",
          run: () => {
            if (!link.handle) return "not connected";
            link.disconnect(true);
            return "disconnecting";
          },
        },
        devices: {
          label: "Devices",
          description: "The Hannes devices the scans found",
          run: () =>
            link.devices.length === 0
              ? "none found yet"
              : link.devices.map((d) => `${d.name} (${d.address}, RSSI ${d.rssi})`).join("; "),
        },
      },
    };
  }

  private process(f: Frame): void {
    const n = f.n;
    if (n === 0) return;
    const { out, act, ref, control, link } = this;
    const o = out.frame(n);
    for (let e = 0; e < n; e++) {
      o.t[e] = f.t[e]!;
      toActuation(control, f.v, e, act);
      handReference(act, ref);
      o.v.set(ref, e * 4);
      if (link.sendReference(ref)) this.sent++;
    }
    out.emit(o);
    if (this.throttle.due(f.t[n - 1]!)) this.describe();
  }

  /** The connect action: scan and connect now, or once the port is open. */
  private connect(arg: unknown): string {
    const link = this.link;
    if (typeof arg === "string" && arg.trim() !== "") link.wanted = arg.trim();
    link.wantConnect = true;
    if (!this.started) return "start the pipeline first";
    if (!link.handle) {
      link.open();
      return `opening ${this.port}; it connects then`;
    }
    if (!link.portOpen) return `waiting for ${this.port} to open; it connects then`;
    link.begin();
    return `scanning for ${link.wanted ?? "a Hannes"}`;
  }

  private describe(): void {
    let s = this.phaseText();
    if (this.link.nacks > 0) s += ` · ${this.link.nacks} NACK`;
    this.ctx.setText(s);
  }

  private phaseText(): string {
    const { port, link } = this;
    switch (link.phase) {
      case "unavailable":
        return "serial ports are not available here (browser build): run the pipeline with mosaic run or the desktop app";
      case "closed":
        return `${port} closed`;
      case "waiting":
        return `${port} open; press connect to find the Hannes`;
      case "opening":
        return `opening ${port}… ${link.detail}`.trim();
      case "dongle":
        return `${port}: dongle in command mode…`;
      case "scanning":
        return `${port}: scanning for a Hannes (attempt ${link.attempt} of ${MAX_SCANS})…`;
      case "connecting":
        return `${port}: connecting to ${link.device?.name ?? "?"}…`;
      case "pinging":
        return `${port}: waiting for ${link.device?.name ?? "the hand"} to acknowledge…`;
      case "configuring":
        return `${port}: configuring ${link.device?.name ?? "the hand"}…`;
      case "streaming":
        return `${link.device?.name ?? "Hannes"} on ${port}, ${this.reads}: ${plural(this.sent, "reference")} sent`;
      case "failed":
        return `${port}: ${link.detail}`;
    }
  }
}
