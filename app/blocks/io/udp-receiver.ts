import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  vectorShape,
  type Endpoint,
  type UdpSocketHandle,
} from "../../engine";
import { plural } from "../shared/text";
import {
  decodeRaw,
  decodeStreamlined,
  counterGap,
  MAX_DATAGRAM_BYTES,
  MAX_STREAMLINED_VALUES,
  newHeader,
  valueSize,
} from "./udp-format";
import {
  byteParam,
  endpointText,
  formatParam,
  hostParam,
  portParam,
  udpBridge,
  WarnLimiter,
} from "./udp-common";

const params = z.strictObject({
  Host: hostParam(
    "Local address to listen on: 127.0.0.1 (default) for this machine only, 0.0.0.0 for every network interface",
  ),
  Port: portParam("Local UDP port to listen on"),
  Format: formatParam,
  Channels: z
    .number()
    .int()
    .min(1)
    .max(MAX_DATAGRAM_BYTES >> 2)
    .describe(
      "Values per event (the output vector's width); streamlined datagrams must carry this many (at most 255)",
    ),
  Category: byteParam(
    "Streamlined only: accept only datagrams of this category (others are counted as ignored); default any",
  ).optional(),
  Subcategory: byteParam(
    "Streamlined only: accept only datagrams of this subcategory; default any",
  ).optional(),
  Timestamps: z
    .enum(["arrival", "sender"])
    .default("arrival")
    .describe(
      "Event timestamps: the arrival time on the pipeline clock, or (streamlined) the timestamp the sender wrote",
    ),
  Scale: z
    .number()
    .default(1)
    .describe("Received values are multiplied by this (1/128 for myo bytes)"),
});

export const UdpReceiver = defineBlock({
  type: "UdpReceiver",
  category: "Communication",
  summary:
    "Listens on a UDP port and emits each datagram's values: streamlined or raw f32/f64 vectors.",
  help:
    "A source for devices and programs that stream over UDP (paper III-E.5, MOSAIC's UDP base " +
    "class). It listens on Host:Port and parses every datagram in the format the UdpSender " +
    "writes (docs/protocols.md): **streamlined** datagrams (MOSAIC's UDP_StreamlinedSender: " +
    "count, type byte, category, subcategory, f64 timestamp, values of any of the ten value " +
    "types, u16 counter) give one event each, with the values converted to numbers; the " +
    "counter reveals lost datagrams, which are counted. **f32** / **f64** datagrams are bare " +
    "little-endian vectors; one datagram may hold several whole vectors (events spaced by " +
    "1/DesiredRate when it is set). Malformed datagrams (wrong length, unknown type byte, " +
    "another channel count) are counted and reported in the status, never thrown. A port " +
    "already in use is reported with the port, and the rest of the pipeline keeps running. " +
    "Unavailable in the browser build (no sockets): the status says so.",
  params,
  inputs: { min: 0, max: 0 },
  eventLoop: true,
  views: ["scope", "label"],
  panel: "Scope of the received values; datagrams received, lost and malformed.",
  create(ctx, p) {
    const streamlined = p.Format === "streamlined";
    const channels = p.Channels;
    if (streamlined && channels > MAX_STREAMLINED_VALUES) {
      throw new BlockConfigError(
        `a streamlined datagram carries at most ${MAX_STREAMLINED_VALUES} values (its count is one byte), not ${channels}: use Format f32 or f64`,
        "Channels",
      );
    }
    if (!streamlined) {
      for (const k of ["Category", "Subcategory"] as const) {
        if (p[k] !== undefined) {
          throw new BlockConfigError(
            `${k} filters streamlined datagrams; Format ${p.Format} datagrams have no header`,
            k,
          );
        }
      }
      if (p.Timestamps === "sender") {
        throw new BlockConfigError(
          `Format ${p.Format} datagrams carry no timestamp: use Timestamps arrival`,
          "Timestamps",
        );
      }
      if (channels * valueSize(p.Format === "f32" ? "f32" : "f64") > MAX_DATAGRAM_BYTES) {
        throw new BlockConfigError(
          `${channels} ${p.Format} values do not fit one UDP datagram (${MAX_DATAGRAM_BYTES} bytes)`,
          "Channels",
        );
      }
    }
    const raw: "f32" | "f64" = p.Format === "f32" ? "f32" : "f64";
    const out = ctx.output(vectorShape(channels));
    const where = endpointText(p.Host, p.Port);
    const scale = p.Scale;
    const senderTime = p.Timestamps === "sender";
    const header = newHeader();
    const maxVectors = streamlined
      ? 1
      : Math.max(1, Math.floor(MAX_DATAGRAM_BYTES / (channels * valueSize(raw))));
    const scratch = new Float64Array(streamlined ? MAX_STREAMLINED_VALUES : maxVectors * channels);
    const warns = new WarnLimiter(ctx);

    let socket: UdpSocketHandle | undefined;
    let listening = false;
    let state: "opening" | "listening" | "closed" = "opening";
    let failure = "";
    let datagrams = 0;
    let events = 0;
    let malformed = 0;
    let lastMalformed = "";
    let ignored = 0;
    let lost = 0;
    let reordered = 0;
    let lastCounter = -1;
    let lastT = -Infinity;
    let lastText = -Infinity;

    const describe = (): void => {
      if (failure !== "") {
        ctx.setText(failure);
        return;
      }
      const parts = [
        state === "listening"
          ? `listening on ${where}`
          : state === "closed"
            ? `closed ${where}`
            : `opening ${where}`,
        `${plural(datagrams, "datagram")}`,
      ];
      if (lost > 0) parts.push(`${lost} lost`);
      if (reordered > 0) parts.push(`${reordered} out of order`);
      if (ignored > 0) parts.push(`${ignored} ignored (other category)`);
      if (malformed > 0) parts.push(`${malformed} malformed (last: ${lastMalformed})`);
      ctx.setText(parts.join(", "));
    };
    const bridge = udpBridge(ctx);
    if (bridge) describe();

    const refuse = (reason: string, from: Endpoint): void => {
      malformed++;
      lastMalformed = reason;
      warns.warn(
        `malformed datagram from ${endpointText(from.host, from.port)} on ${where}: ${reason} (${malformed} so far)`,
      );
      describe();
    };

    const onMessage = (data: Uint8Array, from: Endpoint): void => {
      datagrams++;
      const now = ctx.now();
      if (streamlined) {
        const err = decodeStreamlined(data, header, scratch, 0, MAX_STREAMLINED_VALUES, scale);
        if (err !== undefined) return refuse(err, from);
        if (
          (p.Category !== undefined && header.category !== p.Category) ||
          (p.Subcategory !== undefined && header.subcategory !== p.Subcategory)
        ) {
          ignored++;
        } else if (header.count !== channels) {
          return refuse(`${header.count} values, expected Channels ${channels}`, from);
        } else {
          if (lastCounter >= 0) {
            const gap = counterGap(lastCounter, header.counter);
            if (gap > 0) lost += gap;
            else if (gap < 0) reordered++;
          }
          lastCounter = header.counter;
          const f = out.frame(1);
          f.t[0] = senderTime ? header.timestamp : now;
          const v = f.v;
          for (let i = 0; i < channels; i++) v[i] = scratch[i]!;
          events++;
          out.emit(f);
        }
      } else {
        const k = decodeRaw(data, raw, channels, scratch, maxVectors, scale);
        if (typeof k === "string") return refuse(k, from);
        const f = out.frame(k);
        const rate = ctx.desiredRate;
        for (let i = 0; i < k; i++) {
          let t = rate > 0 ? now - (k - 1 - i) / rate : now;
          if (t < lastT) t = lastT;
          f.t[i] = t;
          lastT = t;
        }
        const v = f.v;
        for (let i = 0, n = k * channels; i < n; i++) v[i] = scratch[i]!;
        events += k;
        out.emit(f);
      }
      if (now - lastText >= 0.25 || now < lastText) {
        lastText = now;
        describe();
      }
    };

    const onError = (message: string): void => {
      if (!listening) {
        // Could not bind: this block stays silent, the rest of the pipeline runs on.
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
        state = "opening";
        try {
          const s = bridge.open({
            bind: { host: p.Host, port: p.Port },
            onMessage,
            onReady: () => {
              listening = true;
              state = "listening";
              describe();
            },
            onError,
          });
          // A bridge may refuse at once (through onError) and still return a handle.
          if (failure === "") socket = s;
          else s.close();
        } catch (e) {
          onError(e instanceof Error ? e.message : String(e));
        }
      },
      stop() {
        const s = socket;
        socket = undefined;
        listening = false;
        if (s) state = "closed";
        s?.close();
        if (bridge && failure === "") describe();
      },
      reset() {
        datagrams = 0;
        events = 0;
        malformed = 0;
        lastMalformed = "";
        ignored = 0;
        lost = 0;
        reordered = 0;
        lastCounter = -1;
        lastT = -Infinity;
        warns.reset();
        if (bridge) describe();
      },
      dispose() {
        const s = socket;
        socket = undefined;
        listening = false;
        s?.close();
      },
      actions: {
        counts: {
          label: "Counts",
          description: "Datagrams received, events emitted, lost, out of order, ignored, malformed",
          run: () =>
            `${datagrams} datagrams, ${events} events, ${lost} lost, ${reordered} out of order, ` +
            `${ignored} ignored, ${malformed} malformed${lastMalformed ? ` (last: ${lastMalformed})` : ""}`,
        },
      },
    };
  },
});
