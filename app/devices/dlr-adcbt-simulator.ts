/**
 * The DLR ADC/BT converter, simulated from its byte format as the original MOSAIC's `DLR_ADCBT`
 * block used it (docs/protocols.md, "DLR ADC/BT"), on a serial device: one end of a socat pty
 * pair (`socat pty,raw,echo=0,link=/tmp/dlr pty,raw,echo=0,link=/tmp/board`: the pipeline opens
 * /tmp/dlr, the simulator /tmp/board), or a real serial port wired to the computer running the
 * pipeline.
 *
 * It waits for the 19-byte commands (`AA 7A`, a code, …, `01 8F FF EF`): the channel count
 * (`03 01`, the count in byte 4) sets the frame size, start (`01 6A`) starts the stream, stop
 * (`01 6B`) stops it. Streaming, it writes `rate` frames per second: `AA 7A`, the length byte
 * 4 + 2·channels + 4, a zero, one big-endian 16-bit value per channel, two zeros, `FF FF`.
 *
 * The values are deterministic: `dlrAdcBtRaw(seed, channel, k)` is the raw 12-bit value of
 * channel c in frame k (k counts the frames sent, from `first`, across stops and restarts), so a
 * test compares what a pipeline logged with `dlrAdcBtVolts`. Faults for tests and demos:
 * `inject(kind)` writes a malformed frame (a bad end mark, a wrong length byte, a truncated frame)
 * or bytes that are no frame before the next frame; `faults.every` does so every N frames.
 *
 * Node only (the `serialport` package, on the main thread); used by the tests and by
 * `mosaic simulate dlr-adcbt`. Written from the format, not from the block's parser.
 */
import { SerialPort } from "serialport";

/** The board's serial settings, as the original opened the port. */
export const DLR_SIM_BAUD_RATE = 115200;
/** Frames per second when not told (the original's source does not say the board's rate). */
export const DLR_SIM_DEFAULT_RATE = 100;
/** Channels streamed before a channel-count command arrives (the original's default count). */
export const DLR_SIM_DEFAULT_CHANNELS = 10;

const START = [0xaa, 0x7a];
const COMMAND_LENGTH = 19;
const COMMAND_TAIL = [0x01, 0x8f, 0xff, 0xef];

export type DlrFault = "badEnd" | "badLength" | "truncated" | "noise";
export const DLR_FAULTS: readonly DlrFault[] = ["badEnd", "badLength", "truncated", "noise"];

export interface DlrAdcBtSimulatorOptions {
  /** The serial device to open (a pty end, /dev/ttyUSB0, COM7). */
  path: string;
  /** Channels streamed until the pipeline's channel-count command (default 10). */
  channels?: number;
  /** Frames per second (default 100; 115200 Bd carries about 11 520 / (2·channels + 8)). */
  rate?: number;
  /** Seed of the signals (default 1). */
  seed?: number;
  /** Index k of the first frame (default 0). */
  first?: number;
  /** Inject a malformed frame every `every` frames, cycling through `kinds` (default: all). */
  faults?: { every: number; kinds?: readonly DlrFault[] };
  /** One line for what happens (commands received, streaming), for the CLI. */
  log?: (line: string) => void;
}

export interface DlrAdcBtSimulator {
  readonly path: string;
  /** Channels of the frames (the last channel-count command's). */
  readonly channels: number;
  readonly rate: number;
  readonly seed: number;
  /** Frames sent (good ones; k of the next frame is `first + sent`). */
  readonly sent: number;
  /** Malformed frames and noise written, by kind. */
  readonly injected: Readonly<Record<DlrFault, number>>;
  /** Commands received, in order ("channels 4", "start", "stop", "unknown 01 99"). */
  readonly commands: readonly string[];
  readonly streaming: boolean;
  /** Writes a malformed frame or noise before the next frame (at once if not streaming). */
  inject(kind: DlrFault): void;
  /** Resolves when at least `n` frames were sent in all. */
  waitForFrames(n: number, timeoutMs?: number): Promise<void>;
  /** Stops streaming and closes the port. */
  close(): Promise<void>;
}

/** A 32-bit hash of (seed, channel, k): the seeded noise, random access. */
function hash3(seed: number, a: number, b: number): number {
  let h = Math.imul(seed ^ 0x2545f491, 0x9e3779b1) ^ Math.imul(a + 1, 0x85ebca77);
  h = Math.imul(h ^ (h >>> 15), 0xc2b2ae3d) ^ Math.imul(b, 0x27d4eb2f);
  h = Math.imul(h ^ (h >>> 13), 0x165667b1);
  return (h ^ (h >>> 16)) >>> 0;
}

/**
 * The raw value (0…4095, a 12-bit converter's range) of channel `channel` (0-based) in frame k: a
 * slow sine per channel (0.2 + 0.15·channel cycles per 100 frames) around mid-scale plus ±24
 * counts of seeded noise.
 */
export function dlrAdcBtRaw(seed: number, channel: number, k: number): number {
  const sine = 1500 * Math.sin((2 * Math.PI * (0.2 + 0.15 * channel) * k) / 100 + channel);
  const noise = (hash3(seed, channel, k) % 49) - 24;
  return Math.max(0, Math.min(4095, Math.round(2048 + sine + noise)));
}

/** The value a reader computes from it, in volts: 5 · raw / 4000 (as the original). */
export function dlrAdcBtVolts(seed: number, channel: number, k: number): number {
  return (5.0 * dlrAdcBtRaw(seed, channel, k)) / 4000.0;
}

/** The frame's bytes for raw values (one per channel). */
export function dlrAdcBtFrame(raw: ArrayLike<number>): Uint8Array {
  const length = 4 + 2 * raw.length + 4;
  const b = new Uint8Array(length);
  b[0] = START[0]!;
  b[1] = START[1]!;
  b[2] = length;
  for (let c = 0; c < raw.length; c++) {
    b[4 + 2 * c] = (raw[c]! >> 8) & 0xff;
    b[5 + 2 * c] = raw[c]! & 0xff;
  }
  b[length - 2] = 0xff;
  b[length - 1] = 0xff;
  return b;
}

/** The bytes of a fault for frames of `channels` channels. */
function faultBytes(kind: DlrFault, channels: number): Uint8Array {
  const zeros = new Array<number>(channels).fill(2048);
  switch (kind) {
    case "badEnd": {
      const f = dlrAdcBtFrame(zeros);
      f[f.length - 1] = 0xfe;
      return f;
    }
    case "badLength": {
      // A frame for one channel more: its length byte is not the one expected.
      return dlrAdcBtFrame([...zeros, 2048]);
    }
    case "truncated":
      return dlrAdcBtFrame(zeros).subarray(0, 4 + channels);
    case "noise":
      return Uint8Array.from({ length: 7 }, (_, i) => 0x10 + i);
  }
}

function checkOptions(o: DlrAdcBtSimulatorOptions): void {
  const channels = o.channels ?? DLR_SIM_DEFAULT_CHANNELS;
  if (!Number.isInteger(channels) || channels < 1 || channels > 123) {
    throw new Error(`channels must be 1…123 (a frame's length is one byte), not ${channels}`);
  }
  const rate = o.rate ?? DLR_SIM_DEFAULT_RATE;
  if (!(rate > 0 && rate <= 5000)) throw new Error(`rate must be in (0, 5000] Hz, not ${rate}`);
  if (o.faults && !(Number.isInteger(o.faults.every) && o.faults.every >= 1)) {
    throw new Error(`faults.every must be a whole number of frames ≥ 1, not ${o.faults.every}`);
  }
}

/** Opens the port and answers the pipeline's commands (see the file comment). */
export async function startDlrAdcBtSimulator(
  o: DlrAdcBtSimulatorOptions,
): Promise<DlrAdcBtSimulator> {
  checkOptions(o);
  const port = new SerialPort({ path: o.path, baudRate: DLR_SIM_BAUD_RATE, autoOpen: false });
  await new Promise<void>((resolve, reject) =>
    port.open((err) =>
      err ? reject(new Error(`cannot open ${o.path}: ${err.message}`)) : resolve(),
    ),
  );
  return new Board(port, o);
}

class Board implements DlrAdcBtSimulator {
  readonly path: string;
  readonly rate: number;
  readonly seed: number;
  channels: number;
  sent = 0;
  injected: Record<DlrFault, number> = { badEnd: 0, badLength: 0, truncated: 0, noise: 0 };
  commands: string[] = [];
  streaming = false;
  private readonly first: number;
  private readonly log: (line: string) => void;
  private pending: Uint8Array[] = [];
  private input = new Uint8Array(0);
  private timer: ReturnType<typeof setInterval> | undefined;
  /** Stream start (ms) and frames sent since. */
  private t0 = 0;
  private sinceStart = 0;
  private faultIndex = 0;
  private closed = false;

  constructor(
    private readonly port: SerialPort,
    private readonly o: DlrAdcBtSimulatorOptions,
  ) {
    this.path = o.path;
    this.channels = o.channels ?? DLR_SIM_DEFAULT_CHANNELS;
    this.rate = o.rate ?? DLR_SIM_DEFAULT_RATE;
    this.seed = o.seed ?? 1;
    this.first = o.first ?? 0;
    this.log = o.log ?? (() => {});
    port.on("data", (d: Buffer) => this.onData(d));
    port.on("error", (e: Error) => this.log(`${this.path}: ${e.message}`));
    port.on("close", () => this.stop());
  }

  inject(kind: DlrFault): void {
    this.pending.push(faultBytes(kind, this.channels));
    this.injected[kind]++;
    if (!this.streaming) this.flushPending();
  }

  async waitForFrames(n: number, timeoutMs = 10_000): Promise<void> {
    const end = Date.now() + timeoutMs;
    while (this.sent < n) {
      if (Date.now() > end) {
        throw new Error(`the simulator sent ${this.sent} frames in ${timeoutMs} ms, not ${n}`);
      }
      await new Promise((r) => setTimeout(r, 10));
    }
  }

  async close(): Promise<void> {
    if (this.closed) return;
    this.closed = true;
    this.stop();
    if (!this.port.isOpen) return;
    await new Promise<void>((resolve) => this.port.drain(() => resolve()));
    await new Promise<void>((resolve) => this.port.close(() => resolve()));
  }

  /** Commands may arrive in any chunks: keep bytes until a whole command is there. */
  private onData(d: Buffer): void {
    const joined = new Uint8Array(this.input.length + d.length);
    joined.set(this.input);
    joined.set(d, this.input.length);
    let at = 0;
    while (joined.length - at >= COMMAND_LENGTH) {
      if (joined[at] !== START[0] || joined[at + 1] !== START[1]) {
        at++;
        continue;
      }
      const cmd = joined.subarray(at, at + COMMAND_LENGTH);
      const tailOk = COMMAND_TAIL.every((b, i) => cmd[COMMAND_LENGTH - 4 + i] === b);
      if (!tailOk) {
        this.log(`not a command (bad tail): ${hex(cmd)}`);
        at++;
        continue;
      }
      this.command(cmd);
      at += COMMAND_LENGTH;
    }
    // Keep at most one command's bytes (a start may be among them).
    this.input = joined.slice(Math.max(at, joined.length - COMMAND_LENGTH + 1));
  }

  private command(cmd: Uint8Array): void {
    const code = (cmd[2]! << 8) | cmd[3]!;
    if (code === 0x0301) {
      const n = cmd[4]!;
      if (n < 1 || n > 123) {
        this.commands.push(`channels ${n} (refused)`);
        this.log(`channel count ${n} refused (1…123)`);
        return;
      }
      this.channels = n;
      this.commands.push(`channels ${n}`);
      this.log(`channel count: ${n} (frames of ${4 + 2 * n + 4} bytes)`);
    } else if (code === 0x016a) {
      this.commands.push("start");
      this.start();
    } else if (code === 0x016b) {
      this.commands.push("stop");
      this.log("stop");
      this.stop();
    } else {
      this.commands.push(`unknown ${hex(cmd.subarray(2, 4))}`);
      this.log(`unknown command ${hex(cmd)}`);
    }
  }

  private start(): void {
    if (this.streaming) return;
    this.streaming = true;
    this.t0 = performance.now();
    this.sinceStart = 0;
    this.log(
      `start: ${this.channels} channels at ${this.rate} Hz from frame ${this.first + this.sent}`,
    );
    this.timer = setInterval(() => this.tick(), Math.max(2, Math.min(20, 500 / this.rate)));
  }

  private stop(): void {
    this.streaming = false;
    if (this.timer) clearInterval(this.timer);
    this.timer = undefined;
  }

  /** Writes the frames due since the start (at most half a second's worth after a stall). */
  private tick(): void {
    if (!this.streaming || !this.port.isOpen) return;
    const due = Math.floor(((performance.now() - this.t0) / 1000) * this.rate);
    const n = Math.min(due - this.sinceStart, Math.ceil(this.rate / 2));
    if (n <= 0) return;
    this.sinceStart = Math.max(this.sinceStart + n, due - Math.ceil(this.rate / 2));
    const parts: Uint8Array[] = [];
    const raw = new Array<number>(this.channels);
    for (let i = 0; i < n; i++) {
      parts.push(...this.pending.splice(0));
      const k = this.first + this.sent;
      for (let c = 0; c < this.channels; c++) raw[c] = dlrAdcBtRaw(this.seed, c, k);
      parts.push(dlrAdcBtFrame(raw));
      this.sent++;
      const every = this.o.faults?.every;
      if (every && this.sent % every === 0) {
        const kinds = this.o.faults?.kinds ?? DLR_FAULTS;
        const kind = kinds[this.faultIndex++ % kinds.length]!;
        this.pending.push(faultBytes(kind, this.channels));
        this.injected[kind]++;
      }
    }
    this.port.write(Buffer.concat(parts));
  }

  private flushPending(): void {
    if (this.pending.length > 0 && this.port.isOpen) this.port.write(Buffer.concat(this.pending));
    this.pending = [];
  }
}

function hex(b: Uint8Array): string {
  return [...b].map((x) => x.toString(16).toUpperCase().padStart(2, "0")).join(" ");
}

/** A whole or decimal number option of `mosaic simulate dlr-adcbt`, checked. */
function numberOption(
  v: Record<string, string | boolean | undefined>,
  name: string,
  integer: boolean,
): number | undefined {
  const raw = v[name];
  if (raw === undefined) return undefined;
  const n = Number(raw);
  if (
    typeof raw !== "string" ||
    raw.trim() === "" ||
    !Number.isFinite(n) ||
    (integer && !Number.isInteger(n))
  ) {
    throw new Error(
      `--${name} must be ${integer ? "a whole number" : "a number"}, not '${String(raw)}'`,
    );
  }
  return n;
}

/**
 * The simulator's options from `mosaic simulate dlr-adcbt`'s (`--port PATH [--channels N]
 * [--rate HZ] [--seed S] [--faults N]`); throws an Error saying what is wrong.
 */
export function dlrAdcBtSimulatorOptions(
  v: Record<string, string | boolean | undefined>,
): DlrAdcBtSimulatorOptions {
  const path = v.port;
  if (typeof path !== "string" || path.trim() === "") {
    throw new Error(
      "--port PATH is required: the serial device the board is on, e.g. one end of a pty pair " +
        "made by `socat pty,raw,echo=0,link=/tmp/dlr pty,raw,echo=0,link=/tmp/board` " +
        "(then --port /tmp/board here and Port: /tmp/dlr in the pipeline)",
    );
  }
  const o: DlrAdcBtSimulatorOptions = { path };
  const channels = numberOption(v, "channels", true);
  const rate = numberOption(v, "rate", false);
  const seed = numberOption(v, "seed", true);
  const every = numberOption(v, "faults", true);
  if (channels !== undefined) o.channels = channels;
  if (rate !== undefined) o.rate = rate;
  if (seed !== undefined) o.seed = seed;
  if (every !== undefined) o.faults = { every };
  checkOptions(o);
  return o;
}
