/**
 * `mosaic bench`, device side: the UDP receiver that plays the prosthesis controller for the
 * bench pipelines, which end in a UdpSender to 127.0.0.1 on a fixed port (one per pipeline, in
 * each file's header). The bench binds that port in its own process (node:dgram) before it starts
 * `mosaic run`, timestamps every datagram on arrival and decodes it independently of the product's
 * code (app/blocks/io/udp-format.ts), from the layout in docs/protocols.md:
 *
 *     | count u8 | type byte u8 | category u8 | subcategory u8 | f64 timestamp | values | u16 counter |
 *
 * little-endian, length 14 + count · size. A ControlAlgorithm's output goes out as one datagram per
 * degree of actuation (count 1), all with the event's timestamp, so the datagrams of one event are
 * grouped by their timestamp. Gaps are found two ways: in the counter (+1 per datagram the sender
 * sent, wrapping at 65535: datagrams lost between the sender and us) and in the timestamps (an
 * event the pipeline never sent: consecutive events more than one period apart).
 */
import { createSocket, type Socket } from "node:dgram";

/** One datagram as received: arrival (performance.now(), ms) and the decoded header. */
export interface Arrival {
  at: number;
  timestamp: number;
  counter: number;
  category: number;
  subcategory: number;
  count: number;
}

export interface UdpRxFigures {
  port: number;
  /** The rate the pipeline should send events at (Hz), the reference for the rate and the gaps. */
  expectedRateHz: number;
  /** Seconds of the steady-state window the counts cover. */
  windowSeconds: number;
  /** Datagrams that arrived in the window, and per second. */
  datagrams: number;
  datagramsPerSecond: number;
  /** Distinct subcategories seen (degrees of actuation for the control serializer). */
  perEvent: number;
  /** Events (datagrams grouped by timestamp) whose first datagram arrived in the window. */
  events: number;
  /** Events per second by arrival time: (n − 1) / (last arrival − first arrival). */
  rateHz: number;
  /** Relative deviation of rateHz from expectedRateHz, %. */
  rateErrorPct: number;
  /** Events per second by the timestamps they carry: (n − 1) / (last − first). */
  timestampRateHz: number;
  /** window × expected rate × perEvent: what a perfect sender delivers in the window. */
  expectedDatagrams: number;
  /** Datagrams missing by the counter, between consecutive datagrams of the window. */
  counterGaps: number;
  /** Events missing by the timestamps (consecutive events more than 1.5 periods apart). */
  missingEvents: number;
  /** Events with fewer datagrams than perEvent (a datagram of the event lost). */
  incompleteEvents: number;
  /** Arrival gap between consecutive events: largest, ms (the device's longest wait). */
  maxArrivalGapMs: number;
  /** Datagrams over the whole run, and those that did not decode. */
  datagramsAll: number;
  malformed: number;
  /** Why a malformed datagram was refused (the first one). */
  firstMalformed?: string;
}

const HEADER = 12;
const COUNTER = 2;

/** Value size of a type byte (0x20 float / 0x10 signed flag + size in bytes), or 0 if unknown. */
function sizeOf(typeByte: number): number {
  const flags = typeByte & 0xf0;
  const size = typeByte & 0x0f;
  if (flags === 0x20) return size === 4 || size === 8 ? size : 0;
  if (flags === 0x10 || flags === 0x00) return [1, 2, 4, 8].includes(size) ? size : 0;
  return 0;
}

/** Decodes a streamlined header; a string says why the datagram is malformed. */
export function decodeHeader(msg: Uint8Array, at: number): Arrival | string {
  if (msg.length < HEADER + COUNTER) return `${msg.length} bytes: shorter than header + counter`;
  const count = msg[0]!;
  const size = sizeOf(msg[1]!);
  if (size === 0) return `unknown type byte 0x${msg[1]!.toString(16)}`;
  const len = HEADER + count * size + COUNTER;
  if (msg.length !== len)
    return `${count} values of ${size} bytes need ${len} bytes, got ${msg.length}`;
  const dv = new DataView(msg.buffer, msg.byteOffset, msg.length);
  return {
    at,
    count,
    category: msg[2]!,
    subcategory: msg[3]!,
    timestamp: dv.getFloat64(4, true),
    counter: dv.getUint16(len - COUNTER, true),
  };
}

/** A receiver bound to 127.0.0.1:port that keeps every arrival until closed. */
export class BenchReceiver {
  readonly arrivals: Arrival[] = [];
  malformed = 0;
  firstMalformed: string | undefined;

  private constructor(
    private readonly socket: Socket,
    readonly port: number,
  ) {
    socket.on("message", (msg) => {
      const at = performance.now();
      const a = decodeHeader(msg, at);
      if (typeof a === "string") {
        this.malformed++;
        this.firstMalformed ??= a;
      } else {
        this.arrivals.push(a);
      }
    });
  }

  /** Binds the port (0: any free one, see `port`); rejects with a message that says what to do
   * when it is taken. */
  static async open(port: number): Promise<BenchReceiver> {
    const socket = createSocket({ type: "udp4", reuseAddr: false });
    await new Promise<void>((resolve, reject) => {
      const onError = (e: NodeJS.ErrnoException): void => {
        socket.close();
        reject(
          new Error(
            e.code === "EADDRINUSE"
              ? `cannot receive the pipeline's datagrams: 127.0.0.1:${port} is in use (another \`mosaic bench\` or a receiver on that port?); stop it and run again`
              : `cannot bind the UDP receiver on 127.0.0.1:${port}: ${e.message}`,
          ),
        );
      };
      socket.once("error", onError);
      socket.bind({ port, address: "127.0.0.1", exclusive: true }, () => {
        socket.off("error", onError);
        resolve();
      });
    });
    return new BenchReceiver(socket, socket.address().port);
  }

  close(): Promise<void> {
    return new Promise((r) => this.socket.close(() => r()));
  }

  /** Figures over the arrivals in [fromMs, toMs] (performance.now() times). */
  figures(fromMs: number, toMs: number, expectedRateHz: number): UdpRxFigures {
    return rxFigures(this.arrivals, fromMs, toMs, expectedRateHz, this.port, {
      malformed: this.malformed,
      firstMalformed: this.firstMalformed,
    });
  }
}

/** The figures of a list of arrivals (pure: tested without sockets). */
export function rxFigures(
  all: readonly Arrival[],
  fromMs: number,
  toMs: number,
  expectedRateHz: number,
  port: number,
  bad: { malformed: number; firstMalformed?: string | undefined } = { malformed: 0 },
): UdpRxFigures {
  const win = all.filter((a) => a.at >= fromMs && a.at <= toMs);
  const windowSeconds = Math.max(0, Math.round(toMs - fromMs) / 1000);
  const subs = new Set(win.map((a) => a.subcategory));
  const perEvent = Math.max(1, subs.size);
  // Events: consecutive datagrams with the same timestamp.
  const events: { at: number; t: number; n: number }[] = [];
  let counterGaps = 0;
  for (let i = 0; i < win.length; i++) {
    const a = win[i]!;
    const last = events[events.length - 1];
    if (last && last.t === a.timestamp) last.n++;
    else events.push({ at: a.at, t: a.timestamp, n: 1 });
    if (i > 0) {
      const d = (a.counter - win[i - 1]!.counter - 1) & 0xffff;
      // More than half the range ahead: a repeated or reordered datagram, not 40,000 lost.
      if (d < 0x8000) counterGaps += d;
    }
  }
  // A partial first or last event (the window cut through it) is not a loss.
  const inner = events.slice(1, -1);
  const incompleteEvents = inner.filter((e) => e.n < perEvent).length;
  const period = 1 / expectedRateHz;
  let missingEvents = 0;
  let maxGap = 0;
  for (let i = 1; i < events.length; i++) {
    const dt = events[i]!.t - events[i - 1]!.t;
    if (dt > 1.5 * period) missingEvents += Math.round(dt / period) - 1;
    maxGap = Math.max(maxGap, events[i]!.at - events[i - 1]!.at);
  }
  const n = events.length;
  const span = n > 1 ? (events[n - 1]!.at - events[0]!.at) / 1000 : NaN;
  const tspan = n > 1 ? events[n - 1]!.t - events[0]!.t : NaN;
  const rateHz = n > 1 ? (n - 1) / span : NaN;
  return {
    port,
    expectedRateHz,
    windowSeconds,
    datagrams: win.length,
    datagramsPerSecond: windowSeconds > 0 ? win.length / windowSeconds : NaN,
    perEvent,
    events: n,
    rateHz,
    rateErrorPct: ((rateHz - expectedRateHz) / expectedRateHz) * 100,
    timestampRateHz: n > 1 ? (n - 1) / tspan : NaN,
    expectedDatagrams: Math.round(windowSeconds * expectedRateHz * perEvent),
    counterGaps,
    missingEvents,
    incompleteEvents,
    maxArrivalGapMs: maxGap,
    datagramsAll: all.length,
    malformed: bad.malformed,
    ...(bad.firstMalformed !== undefined ? { firstMalformed: bad.firstMalformed } : {}),
  };
}
