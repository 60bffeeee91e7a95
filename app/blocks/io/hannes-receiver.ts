import { z } from "zod";
import {
  defineBlock,
  LegacyParamsError,
  legacyInteger,
  vectorShape,
  type Endpoint,
  type UdpSocketHandle,
} from "../../engine";
import { timerInput } from "../shared/inputs";
import { plural, TextThrottle } from "../shared/text";
import { decodeHannesEmg } from "./hannes-protocol";
import { endpointText, portParam, udpBridge, WarnLimiter } from "./udp-common";

const params = z.strictObject({
  Port: portParam("The UDP port to listen on (the original listened on every address)"),
  Host: z
    .string()
    .trim()
    .min(1)
    .max(253)
    .regex(/^[A-Za-z0-9.:_%-]+$/, "expected an IP address or a host name")
    .default("0.0.0.0")
    .describe(
      "The local address to bind: 0.0.0.0 for every interface (the original's), 127.0.0.1 for this computer only",
    ),
  Channels: z
    .number()
    .int()
    .min(1)
    .max(1000)
    .default(6)
    .describe(
      "EMG values per datagram, each a little-endian u16 from byte 2 on, divided by 2¹⁶ (the " +
        "original decoded 6 whatever its numEMGs said)",
    ),
  MaxDelay: z
    .number()
    .int()
    .min(1)
    .max(100_000)
    .default(10)
    .describe(
      "With a timer input: samples kept waiting for ticks; older ones are dropped and counted " +
        "(the original's MAX_DELAY, 10)",
    ),
});

export const HannesReceiver = defineBlock({
  type: "HannesReceiver",
  category: "Devices",
  summary: "Receives EMG from IIT's Hannes over UDP: six 16-bit channels per datagram.",
  help:
    "MOSAIC's HannesReceiver (docs/protocols.md, Hannes): listens on a UDP port for the Hannes " +
    "EMG stream. A datagram holds a 2-byte header (not checked, as in the original) and then " +
    "`Channels` little-endian unsigned 16-bit values, each divided by 2¹⁶ (0 ≤ value < 1); " +
    "shorter datagrams are counted as malformed. With a timer input (MOSAIC's form) each tick " +
    "emits the oldest received sample, at most `MaxDelay` samples wait (older ones are dropped " +
    "and counted, as the original's MAX_DELAY), and a tick without a new sample repeats the last " +
    "one (counted; zeros before the first; the original sent zeros, and zeros again on every " +
    "tick that dropped samples). Without an input every datagram is one event at its arrival. " +
    "The socket opens when the pipeline starts (the original waited for its panel's Connect). " +
    "MOSAIC's positional form is `[udpPort, numEMGs]`.",
  params,
  legacyParams(args) {
    if (args.length !== 2) {
      throw new LegacyParamsError(
        `expected [udpPort, numEMGs] (MOSAIC's HannesReceiver), got ${args.length} argument${args.length === 1 ? "" : "s"}`,
      );
    }
    return {
      Port: legacyInteger(args[0]!, "port", "Port"),
      Channels: legacyInteger(args[1]!, "numEMGs", "Channels"),
    };
  },
  legacyForm: "[udpPort, numEMGs], e.g. [11000, 6]",
  inputs: { min: 0, max: 1, labels: ["timer"] },
  eventLoop: true,
  views: ["scope", "label"],
  panel: "The EMG values; datagrams received, samples dropped and repeated.",
  create(ctx, p) {
    const paced = ctx.inputs.length > 0;
    if (paced) timerInput(ctx, 0);
    const C = p.Channels;
    const out = ctx.output(vectorShape(C));
    const where = endpointText(p.Host, p.Port);
    const warns = new WarnLimiter(ctx);
    const throttle = new TextThrottle();
    // FIFO of samples waiting for ticks (paced only).
    const cap = p.MaxDelay;
    const fifo = new Float64Array(cap * C);
    let head = 0;
    let count = 0;
    const last = new Float64Array(C);
    const scratch = new Float64Array(C);
    let datagrams = 0;
    let malformed = 0;
    let dropped = 0;
    let repeated = 0;
    let failure = "";
    let listening = false;
    let socket: UdpSocketHandle | undefined;

    const describe = (): void => {
      if (failure !== "") {
        ctx.setText(failure);
        return;
      }
      const parts = [
        `${listening ? "listening on" : "opening"} ${where}`,
        plural(datagrams, "datagram"),
      ];
      if (dropped > 0) parts.push(`${dropped} dropped (MaxDelay)`);
      if (repeated > 0) parts.push(`${repeated} ticks without a new sample`);
      if (malformed > 0) parts.push(`${malformed} malformed`);
      ctx.setText(parts.join(", "));
    };
    const bridge = udpBridge(ctx);
    if (bridge) describe();

    const onMessage = (data: Uint8Array, from: Endpoint): void => {
      datagrams++;
      if (!decodeHannesEmg(data, C, scratch)) {
        malformed++;
        warns.warn(
          `malformed datagram from ${endpointText(from.host, from.port)} on ${where}: ${data.length} bytes, ` +
            `${2 + 2 * C} needed for ${C} channels`,
        );
        describe();
        return;
      }
      if (!paced) {
        const f = out.frame(1);
        f.t[0] = ctx.now();
        f.v.set(scratch);
        last.set(scratch);
        out.emit(f);
        return;
      }
      if (count === cap) {
        // Drop the oldest: keep the MaxDelay newest.
        head = (head + 1) % cap;
        count--;
        dropped++;
      }
      fifo.set(scratch, ((head + count) % cap) * C);
      count++;
    };

    const onError = (message: string): void => {
      if (!listening) {
        failure = `cannot listen on UDP ${where}: ${message}`;
        const s = socket;
        socket = undefined;
        s?.close();
      }
      warns.warn(listening ? `UDP ${where}: ${message}` : failure);
      describe();
    };

    return {
      start() {
        if (!bridge) {
          ctx.warn(
            "UDP is unavailable here (the browser build has no network sockets): this block receives nothing",
          );
          return;
        }
        if (socket) return;
        failure = "";
        try {
          const s = bridge.open({
            bind: { host: p.Host, port: p.Port },
            onMessage,
            onReady: () => {
              listening = true;
              describe();
            },
            onError,
          });
          if (failure === "") socket = s;
          else s.close();
        } catch (e) {
          onError(e instanceof Error ? e.message : String(e));
        }
      },
      process(f) {
        const n = f.n;
        if (n === 0) return;
        const o = out.frame(n);
        for (let e = 0; e < n; e++) {
          o.t[e] = f.t[e]!;
          if (count > 0) {
            last.set(fifo.subarray(head * C, (head + 1) * C));
            head = (head + 1) % cap;
            count--;
          } else {
            repeated++;
          }
          o.v.set(last, e * C);
        }
        out.emit(o);
        if (throttle.due(f.t[n - 1]!)) describe();
      },
      stop() {
        const s = socket;
        socket = undefined;
        listening = false;
        s?.close();
      },
      reset() {
        head = 0;
        count = 0;
        last.fill(0);
        datagrams = 0;
        malformed = 0;
        dropped = 0;
        repeated = 0;
        warns.reset();
        throttle.reset();
        if (bridge) describe();
      },
      dispose() {
        const s = socket;
        socket = undefined;
        s?.close();
      },
    };
  },
});
