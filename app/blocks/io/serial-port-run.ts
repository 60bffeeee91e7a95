/**
 * One SerialPort block at run time: opens the port, emits each frame the device sends, writes
 * each input event in the same framing, and says the port's state and counts in the status (the
 * behaviour is described in the block's help, serial-port.ts).
 */
import type {
  BlockContext,
  BlockInstance,
  Frame,
  OutputPort,
  SerialHandle,
  SerialStatus,
} from "../../engine";
import type { Decoder, Encoder } from "./serial-framing";

/** The port's settings, as the block's params give them. */
export interface SerialPortSettings {
  Path: string;
  BaudRate: number;
  DataBits: 5 | 6 | 7 | 8;
  StopBits: 1 | 1.5 | 2;
  Parity: "none" | "even" | "odd" | "mark" | "space";
  Reconnect: number;
}

export class SerialPortRun {
  private handle: SerialHandle | undefined;
  private state: SerialStatus | "unavailable" = "closed";
  private message = "";
  private written = 0;
  private writeErrors = 0;
  private lastText = "";

  constructor(
    private readonly ctx: BlockContext,
    private readonly p: SerialPortSettings,
    private readonly decoder: Decoder,
    private readonly encoder: Encoder,
    private readonly out: OutputPort,
    /** The Port info action's text after the settings, framing and frame count. */
    private readonly info: () => string,
  ) {}

  instance(): BlockInstance {
    return {
      start: () => this.start(),
      stop: () => {
        this.close();
        if (this.state !== "unavailable") this.state = "closed";
        this.refresh();
      },
      process: (frame: Frame) => this.process(frame),
      reset: () => this.reset(),
      dispose: () => this.close(),
      actions: {
        info: {
          label: "Port info",
          description: "Shows the port settings and counters",
          run: () =>
            `${this.info()}: ${this.decoder.stats.frames} frames, ` +
            `${this.decoder.stats.malformed} malformed, ${this.written} written`,
        },
      },
    };
  }

  private start(): void {
    const bridge = this.ctx.io.serial;
    if (!bridge) {
      this.state = "unavailable";
      this.refresh();
      return;
    }
    const p = this.p;
    this.handle = bridge.open({
      path: p.Path,
      baudRate: p.BaudRate,
      dataBits: p.DataBits,
      stopBits: p.StopBits,
      parity: p.Parity,
      reconnectMs: p.Reconnect * 1000,
      onData: (bytes) => this.onData(bytes),
      onStatus: (s, msg) => this.onStatus(s, msg),
    });
  }

  private close(): void {
    this.handle?.close();
    this.handle = undefined;
  }

  /** Writes every input event to the device while the port is open; counts them otherwise. */
  private process(frame: Frame): void {
    const handle = this.handle;
    if (!handle || this.state !== "open") {
      this.writeErrors += frame.n;
      this.refresh();
      return;
    }
    const width = frame.stride;
    for (let e = 0; e < frame.n; e++) {
      handle.write(this.encoder.encode(frame.v.subarray(e * width, (e + 1) * width)));
      this.written++;
    }
    this.refresh();
  }

  /** As if just created, the port left as it is: a partial frame dropped, every count zero. */
  private reset(): void {
    this.decoder.reset();
    Object.assign(this.decoder.stats, { frames: 0, malformed: 0, skipped: 0, lastProblem: "" });
    this.written = 0;
    this.writeErrors = 0;
    this.refresh();
  }

  private readonly emit = (values: ArrayLike<number>): void => {
    const f = this.out.frame(1);
    f.t[0] = this.ctx.now();
    f.v.set(values);
    this.out.emit(f);
  };

  private onData(bytes: Uint8Array): void {
    const decoder = this.decoder;
    const before = decoder.stats.malformed;
    decoder.push(bytes, this.emit);
    if (decoder.stats.malformed !== before) {
      this.ctx.warn(`${this.p.Path}: ${decoder.stats.lastProblem}`);
    }
    this.refresh();
  }

  private onStatus(s: SerialStatus, msg?: string): void {
    const was = this.state;
    this.state = s;
    this.message = msg ?? "";
    if (s === "error" && was !== "error") this.ctx.warn(`${this.p.Path}: ${this.message}`);
    if (s !== "open") this.decoder.reset();
    this.refresh();
  }

  private refresh(): void {
    const s = this.decoder.stats;
    let text = this.stateText();
    if (this.written > 0) text += ` · ${this.written} written`;
    if (s.malformed > 0) text += ` · ${s.malformed} malformed (last: ${s.lastProblem})`;
    if (s.skipped > 0) text += ` · ${s.skipped} bytes skipped`;
    if (this.writeErrors > 0) text += ` · ${this.writeErrors} writes failed`;
    if (text !== this.lastText) {
      this.lastText = text;
      this.ctx.setText(text);
    }
  }

  private stateText(): string {
    const p = this.p;
    switch (this.state) {
      case "unavailable":
        return "serial ports are not available here (browser build): run the pipeline with mosaic run or the desktop app";
      case "open":
        return `${p.Path} open @ ${p.BaudRate} Bd · ${this.decoder.stats.frames} frames`;
      case "opening":
        return `opening ${p.Path}…`;
      case "closed":
        return `${p.Path} closed`;
      case "error":
        return `${p.Path}: ${this.message}`;
    }
  }
}
