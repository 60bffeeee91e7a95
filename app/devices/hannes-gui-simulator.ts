/**
 * IIT's Hannes GUI (a virtual Hannes arm) as MOSAIC's HannesGUI block talks to it, written from
 * the datagram formats in docs/protocols.md ("Hannes", HannesGUI), not from the block's code: a
 * UDP listener (default 127.0.0.1:8889, the original's examples' port) that decodes each
 * datagram `%`, kind, payload, `&`, CR, LF:
 *   - 15 activation: joint (0 hand, 1 wrist P/S, 2 wrist F/E) and value 0…100, one byte each;
 *   - 16 raw EMG: one signed byte per value (128·x);
 *   - 32 ARV: little-endian float64 values.
 * Anything else (no frame, an unknown kind, a wrong length, a joint or value out of range) is
 * counted by kind, never thrown. It keeps the arm's state (the three activations, the last raw
 * EMG and ARV vectors) and reports it in one compact line when it changes, at most four a second.
 * Used by the tests and by `mosaic simulate hannes-gui`.
 */
import { createSocket, type Socket } from "node:dgram";
import {
  checkPort,
  DeviceUnavailableError,
  errorText,
  FRAME_END,
  FRAME_START,
  hex,
  int8,
  logsFault,
  numberOption,
  StateReporter,
  type SimulatorValues,
} from "./hannes-simulator-common";

/** The port the original's examples sent to. */
export const HANNES_GUI_PORT = 8889;

/** A decoded datagram. */
export type GuiDatagram =
  | { kind: "activation"; joint: number; value: number }
  | { kind: "raw"; values: number[] }
  | { kind: "arv"; values: number[] }
  | { kind: "malformed"; fault: GuiFault; why: string };

export type GuiFault = "notFramed" | "unknownKind" | "badLength" | "badValue";
const FAULT_TEXT: Record<GuiFault, string> = {
  notFramed: "not framed",
  unknownKind: "unknown kind",
  badLength: "bad length",
  badValue: "bad value",
};

/** Decodes one datagram (see the file comment). */
export function decodeGuiDatagram(d: Uint8Array): GuiDatagram {
  const n = d.length;
  const framed = n >= 5 && d[0] === FRAME_START && FRAME_END.every((x, i) => d[n - 3 + i] === x);
  if (!framed) return bad("notFramed", `${n} bytes: ${hex(d, 12)}`);
  const kind = d[1]!;
  const body = d.subarray(2, n - 3);
  if (kind === 15) {
    if (body.length !== 2) return bad("badLength", `activation with ${body.length} bytes, not 2`);
    const [joint, value] = [body[0]!, body[1]!];
    if (joint > 2 || value > 100) {
      return bad("badValue", `activation of joint ${joint} to ${value} (joints 0…2, values 0…100)`);
    }
    return { kind: "activation", joint, value };
  }
  if (kind === 16) return { kind: "raw", values: Array.from(body, int8) };
  if (kind === 32) {
    if (body.length % 8 !== 0) return bad("badLength", `ARV with ${body.length} bytes, not 8·k`);
    const dv = new DataView(body.buffer, body.byteOffset, body.length);
    return {
      kind: "arv",
      values: Array.from({ length: body.length / 8 }, (_, i) => dv.getFloat64(8 * i, true)),
    };
  }
  return bad("unknownKind", `kind ${kind} (15, 16 and 32 known)`);
}

function bad(fault: GuiFault, why: string): GuiDatagram {
  return { kind: "malformed", fault, why };
}

export interface HannesGuiSimulatorOptions {
  /** Address to listen on (default 127.0.0.1). */
  host?: string;
  /** UDP port (default 8889; 0: any free port). */
  port?: number;
  /** Keep every decoded datagram in `received` (tests). */
  record?: boolean;
  /** The arm's state and malformed datagrams, one line each (the CLI prints them). */
  log?: (line: string) => void;
}

/** The virtual arm's state: activations of hand, wrist P/S and wrist F/E; last raw EMG and ARVs. */
export interface GuiState {
  activation: [number, number, number];
  raw: number[];
  arv: number[];
}

/** Starts listening; rejects (exit status 1 from the CLI) when the port is taken. */
export async function startHannesGuiSimulator(
  o: HannesGuiSimulatorOptions = {},
): Promise<HannesGuiSimulator> {
  const host = o.host ?? "127.0.0.1";
  const port = o.port ?? HANNES_GUI_PORT;
  checkPort(port, "the port");
  const socket = createSocket(host.includes(":") ? "udp6" : "udp4");
  await new Promise<void>((resolve, reject) => {
    const onError = (e: NodeJS.ErrnoException): void => {
      socket.close();
      const why = e.code === "EADDRINUSE" ? "is in use (another Hannes GUI?)" : errorText(e);
      reject(new DeviceUnavailableError(`UDP ${host}:${port} ${why}`));
    };
    socket.once("error", onError);
    socket.bind(port, host, () => {
      socket.off("error", onError);
      resolve();
    });
  });
  return new HannesGuiSimulator(socket, host, o);
}

export class HannesGuiSimulator {
  readonly host: string;
  readonly port: number;
  /** Every datagram decoded, in order, when `record` is on. */
  readonly received: GuiDatagram[] = [];
  readonly counts = { activation: 0, raw: 0, arv: 0 };
  readonly malformed: Record<GuiFault, number> = {
    notFramed: 0,
    unknownKind: 0,
    badLength: 0,
    badValue: 0,
  };
  readonly state: GuiState = { activation: [0, 0, 0], raw: [], arv: [] };
  private readonly reporter: StateReporter;
  private readonly log: (line: string) => void;
  private closed = false;

  constructor(
    private readonly socket: Socket,
    host: string,
    private readonly o: HannesGuiSimulatorOptions,
  ) {
    this.host = host;
    this.port = socket.address().port;
    this.log = o.log ?? (() => {});
    this.reporter = new StateReporter(this.log);
    socket.on("message", (m: Buffer) => this.onDatagram(m));
    socket.on("error", (e) => this.log(`UDP ${this.host}:${this.port}: ${errorText(e)}`));
  }

  /** Datagrams decoded (good ones). */
  get datagrams(): number {
    return this.counts.activation + this.counts.raw + this.counts.arv;
  }

  get malformedTotal(): number {
    return Object.values(this.malformed).reduce((s, x) => s + x, 0);
  }

  /** The state in one compact line. */
  stateText(): string {
    const [hand, ps, fe] = this.state.activation;
    let s = `hand ${hand} · wrist P/S ${ps} · wrist F/E ${fe}`;
    if (this.counts.raw > 0) s += ` · raw EMG ${vectorText(this.state.raw, 0)}`;
    if (this.counts.arv > 0) s += ` · ARV ${vectorText(this.state.arv, 3)}`;
    s += ` · ${this.datagrams} datagrams`;
    if (this.malformedTotal > 0) {
      const parts = (Object.keys(this.malformed) as GuiFault[])
        .filter((k) => this.malformed[k] > 0)
        .map((k) => `${this.malformed[k]} ${FAULT_TEXT[k]}`);
      s += ` · malformed: ${parts.join(", ")}`;
    }
    return s;
  }

  async waitFor(cond: () => boolean, what: string, timeoutMs = 10_000): Promise<void> {
    const end = Date.now() + timeoutMs;
    while (!cond()) {
      if (Date.now() > end)
        throw new Error(`the Hannes GUI simulator: no ${what} in ${timeoutMs} ms`);
      await new Promise((r) => setTimeout(r, 10));
    }
  }

  async close(): Promise<void> {
    if (this.closed) return;
    this.closed = true;
    this.reporter.flush();
    await new Promise<void>((r) => this.socket.close(() => r()));
  }

  private onDatagram(m: Buffer): void {
    const d = decodeGuiDatagram(m);
    if (this.o.record) this.received.push(d);
    switch (d.kind) {
      case "activation":
        this.state.activation[d.joint] = d.value;
        this.counts.activation++;
        break;
      case "raw":
        this.state.raw = d.values;
        this.counts.raw++;
        break;
      case "arv":
        this.state.arv = d.values;
        this.counts.arv++;
        break;
      case "malformed":
        this.malformed[d.fault]++;
        if (logsFault(this.malformedTotal)) {
          this.log(`malformed datagram ${this.malformedTotal}: ${FAULT_TEXT[d.fault]}: ${d.why}`);
        }
        break;
    }
    this.reporter.update(this.stateText());
  }
}

/** A vector, compactly: "[8] 12 -3 40 … max |x| 40" for long ones. */
function vectorText(v: readonly number[], digits: number): string {
  const f = (x: number): string => (digits === 0 ? String(x) : x.toFixed(digits));
  const shown = v.slice(0, 4).map(f).join(" ");
  const more = v.length > 4 ? " …" : "";
  const peak = v.reduce((m, x) => Math.max(m, Math.abs(x)), 0);
  return `[${v.length}] ${shown}${more} (max |x| ${f(peak)})`;
}

/** The simulator's options from `mosaic simulate hannes-gui`'s (`[--host ADDR] [--port P]`). */
export function hannesGuiSimulatorOptions(v: SimulatorValues): HannesGuiSimulatorOptions {
  const o: HannesGuiSimulatorOptions = {};
  if (typeof v.host === "string") {
    if (v.host.trim() === "") throw new Error("--host must be an address, not empty");
    o.host = v.host.trim();
  }
  const port = numberOption(v, "port", { integer: true, min: 0, max: 65535 });
  if (port !== undefined) o.port = port;
  return o;
}
