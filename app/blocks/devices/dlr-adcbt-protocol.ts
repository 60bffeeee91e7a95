/**
 * The DLR ADC/BT link: an analog-to-digital converter behind a serial port (Bluetooth SPP or
 * USB) at 115200 Bd 8N1, as the original MOSAIC's `DLR_ADCBT` spoke to it (docs/protocols.md,
 * "DLR ADC/BT"): once the port is open, the channel-count command, then start; the board then
 * streams fixed-size frames (dlr-adcbt-frames.ts), each one sample of every channel in volts.
 *
 * The port comes from the host's serial bridge (`ctx.io.serial`), which keeps it open: after an
 * unplug it reports the reason and reopens it every second, and this module configures the board
 * again when it is back. A board that stops sending while the port stays open (switched off, out
 * of Bluetooth range, a simulator that closed its end of a pty) is reported lost after
 * DLR_SILENCE_S, and configured again every second until frames come back. The status says where
 * the link is ("lost … reconnecting", then "streaming … reconnected N×") and counts malformed
 * frames and skipped bytes; a malformed frame is dropped and the parser re-synchronises on the
 * next start bytes.
 */
import type { BlockContext, SerialHandle, SerialStatus } from "../../engine";
import { plural } from "../shared/text";
import { DlrFrameParser, dlrCommand, dlrFrameLength } from "./dlr-adcbt-frames";
import type { DeviceProtocol, DeviceSampleSink } from "./paced-device";

export const DLR_BAUD_RATE = 115200;
/** Channels when the file does not say (the original's default). */
export const DLR_DEFAULT_CHANNELS = 10;
/** A frame's length is one byte: 4 + 2 · channels + 4 ≤ 255. */
export const DLR_MAX_CHANNELS = 123;
/** How often the bridge tries to reopen a lost or missing port. */
export const DLR_RECONNECT_MS = 1000;
/** A streaming board that sends no frame for this long (s) is reported lost. */
export const DLR_SILENCE_S = 1;

/** The browser build's status (no serial bridge there). */
export const DLR_NO_SERIAL =
  "serial ports are not available here (browser build): run the pipeline with mosaic run or the desktop app; sending zeros";

/** "…; retrying every 1 s" (the bridge's words) → "… — reconnecting every 1 s". */
function reconnecting(message: string): string {
  return message.replace(/; retrying every (.+)$/, " — reconnecting every $1");
}

/** What to do without the board, said with the first failure to open its port. */
const DLR_WITHOUT_BOARD =
  "without the board: mosaic run --simulate-devices, or a simulated board: mosaic simulate dlr-adcbt --port PATH";

/** The protocol module for `DLR_ADCBT` (see the file comment). */
export function dlrAdcBtProtocol(link: {
  Port?: string | undefined;
  Channels: number;
}): DeviceProtocol {
  return {
    open(ctx, sink) {
      const path = link.Port;
      if (!path) {
        sink.state(
          "lost",
          "no serial port chosen: set Port (e.g. /dev/rfcomm0, /dev/ttyUSB0 or COM5); sending zeros",
        );
        sink.warn("no serial port chosen (Port is not set): the block sends zeros");
        return undefined;
      }
      const bridge = ctx.io.serial;
      if (!bridge) {
        sink.state("lost", DLR_NO_SERIAL);
        sink.warn(
          `serial ports are not available here (browser build), so the DLR ADC/BT on serial port ${path} ` +
            `at ${DLR_BAUD_RATE} Bd is not reachable: run the pipeline with mosaic run or the desktop app (the block sends zeros)`,
        );
        return undefined;
      }
      const dlr = new DlrLink(ctx, path, link.Channels, sink);
      dlr.handle = bridge.open({
        path,
        baudRate: DLR_BAUD_RATE,
        dataBits: 8,
        stopBits: 1,
        parity: "none",
        reconnectMs: DLR_RECONNECT_MS,
        onData: (bytes) => dlr.onData(bytes),
        onStatus: (s, m) => dlr.onStatus(s, m),
      });
      return { close: () => dlr.close() };
    },
  };
}

type Phase = "opening" | "failing" | "configured" | "streaming" | "lost" | "silent" | "closed";

/** One block's link to the board: the port's states, the parser, the watchdog and the status. */
class DlrLink {
  handle: SerialHandle | undefined;
  private readonly parser: DlrFrameParser;
  private phase: Phase = "opening";
  private detail = "";
  /** Streaming resumed after a loss (the port, or silence). */
  private reconnects = 0;
  private wasLost = false;
  /** Configurations sent since the port opened or the frames stopped. */
  private configs = 0;
  private lastFrame = 0;
  private lastConfig = 0;
  private lastWarning = "";
  private shownMalformed = 0;
  private shownSkipped = 0;

  constructor(
    private readonly ctx: BlockContext,
    private readonly path: string,
    private readonly channels: number,
    private readonly sink: DeviceSampleSink,
  ) {
    this.parser = new DlrFrameParser(channels);
    this.watch();
  }

  onStatus(s: SerialStatus, message = ""): void {
    switch (s) {
      case "opening":
        // A retry after a loss keeps saying that the link is lost.
        if (this.phase === "opening") this.describe();
        return;
      case "open":
        this.parser.clear();
        this.configs = 0;
        this.configure();
        this.phase = "configured";
        this.describe();
        return;
      case "error": {
        const wasOpen = this.phase !== "opening" && this.phase !== "failing";
        if (this.phase === "streaming" || this.phase === "silent") this.wasLost = true;
        this.phase = wasOpen ? "lost" : "failing";
        this.detail = message;
        this.warnOnce(
          wasOpen
            ? `lost ${this.path}: ${message}`
            : `cannot open ${this.path}: ${message} (${DLR_WITHOUT_BOARD})`,
        );
        this.describe();
        return;
      }
      case "closed":
        this.phase = "closed";
        return;
    }
  }

  onData(bytes: Uint8Array): void {
    if (this.phase === "closed") return;
    const sink = this.sink;
    let any = false;
    this.parser.push(bytes, (volts) => {
      sink.push(volts);
      any = true;
    });
    const s = this.parser.stats;
    const news = s.malformed !== this.shownMalformed || s.skipped !== this.shownSkipped;
    if (s.malformed !== this.shownMalformed) sink.warn(`${this.path}: ${s.lastProblem}`);
    if (any) {
      this.lastFrame = this.ctx.now();
      if (this.phase !== "streaming") {
        if (this.wasLost) this.reconnects++;
        this.wasLost = false;
        this.phase = "streaming";
        this.describe();
        return;
      }
    }
    if (news) this.describe();
  }

  close(): void {
    const h = this.handle;
    this.handle = undefined;
    if (h && this.phase !== "closed") {
      // Not something the original sent (it only stopped reading); the board stops streaming.
      h.write(dlrCommand("stop"));
    }
    this.phase = "closed";
    h?.close();
  }

  /**
   * Every half second while the link is not closed: a board that sent no frame for
   * DLR_SILENCE_S (switched off, out of radio range, restarted) is reported lost, and while the
   * port is open without frames the configuration goes again every second (a board that was
   * restarted waits for it). Also while lost: after a failed write the port may still be open
   * (the bridge drops writes to a closed one).
   */
  private watch(): void {
    const check = (now: number): void => {
      if (this.phase === "closed") return;
      if (this.phase === "streaming" && now - this.lastFrame > DLR_SILENCE_S) {
        this.phase = "silent";
        this.wasLost = true;
        this.configs = 0;
        this.warnOnce(`lost ${this.path}: no frames for ${DLR_SILENCE_S} s`);
        this.describe();
      }
      if (
        (this.phase === "configured" || this.phase === "silent" || this.phase === "lost") &&
        now - this.lastConfig >= DLR_RECONNECT_MS / 1000
      ) {
        this.configure();
        this.describe();
      }
      this.ctx.at(now + 0.5, check);
    };
    this.ctx.at(this.ctx.now() + 0.5, check);
  }

  /** What the original wrote once the port was open: the channel count, then start. */
  private configure(): void {
    this.lastConfig = this.ctx.now();
    this.configs++;
    this.handle?.write(dlrCommand("channels", this.channels));
    this.handle?.write(dlrCommand("start"));
  }

  private warnOnce(warning: string): void {
    if (warning === this.lastWarning) return;
    this.lastWarning = warning;
    this.sink.warn(warning);
  }

  private describe(): void {
    const s = this.parser.stats;
    this.shownMalformed = s.malformed;
    this.shownSkipped = s.skipped;
    const reconnects = this.reconnects > 0 ? ` · reconnected ${this.reconnects}×` : "";
    let counts = "";
    if (s.malformed > 0) {
      counts += ` · ${plural(s.malformed, "malformed frame")} (last: ${s.lastProblem})`;
    }
    if (s.skipped > 0) counts += ` · ${plural(s.skipped, "byte")} skipped`;
    const sent = this.configs > 1 ? ` (configuration sent ${this.configs} times)` : "";
    switch (this.phase) {
      case "opening":
        this.sink.state("connecting", `opening ${this.path}…`);
        return;
      case "failing":
        this.sink.state(
          "connecting",
          `cannot open ${this.path}: ${reconnecting(this.detail)} (sending zeros)`,
        );
        return;
      case "configured":
        this.sink.state(
          "connecting",
          `${this.path} open, ${plural(this.channels, "channel")} configured; waiting for frames…${sent}${reconnects}${counts}`,
        );
        return;
      case "streaming":
        this.sink.state(
          "streaming",
          `streaming from ${this.path} (${plural(this.channels, "channel")}, ${dlrFrameLength(this.channels)}-byte frames, ${DLR_BAUD_RATE} Bd)${reconnects}${counts}`,
        );
        return;
      case "lost":
        this.sink.state("lost", `lost ${this.path}: ${reconnecting(this.detail)}${counts}`);
        return;
      case "silent":
        this.sink.state(
          "lost",
          `lost ${this.path}: no frames for ${DLR_SILENCE_S} s (board off or out of range?) — reconnecting: configuring it every ${DLR_RECONNECT_MS / 1000} s${sent}${counts}`,
        );
        return;
      case "closed":
        return;
    }
  }
}
