import { z } from "zod";
import { BlockConfigError, defineBlock, vectorShape } from "../../engine";
import { MAX_DATAGRAM_BYTES, MAX_STREAMLINED_VALUES, valueSize } from "./udp-format";
import { byteParam, formatParam, hostParam, portParam, udpBridge } from "./udp-common";
import { UdpReceiverRun } from "./udp-receiver-run";

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

type Params = z.output<typeof params>;

/** Channels and the streamlined-only params against the format. */
function checkParams(p: Params): void {
  const channels = p.Channels;
  if (p.Format === "streamlined") {
    if (channels > MAX_STREAMLINED_VALUES) {
      throw new BlockConfigError(
        `a streamlined datagram carries at most ${MAX_STREAMLINED_VALUES} values (its count is one byte), not ${channels}: use Format f32 or f64`,
        "Channels",
      );
    }
    return;
  }
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
  if (channels * valueSize(p.Format) > MAX_DATAGRAM_BYTES) {
    throw new BlockConfigError(
      `${channels} ${p.Format} values do not fit one UDP datagram (${MAX_DATAGRAM_BYTES} bytes)`,
      "Channels",
    );
  }
}

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
    checkParams(p);
    const settings = {
      host: p.Host,
      port: p.Port,
      streamlined: p.Format === "streamlined",
      raw: p.Format === "f32" ? ("f32" as const) : ("f64" as const),
      channels: p.Channels,
      category: p.Category,
      subcategory: p.Subcategory,
      senderTime: p.Timestamps === "sender",
      scale: p.Scale,
    };
    const out = ctx.output(vectorShape(p.Channels));
    return new UdpReceiverRun(ctx, settings, out, udpBridge(ctx)).instance();
  },
});
