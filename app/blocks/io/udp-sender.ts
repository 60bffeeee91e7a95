import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  LegacyParamsError,
  legacyInteger,
  type BlockContext,
  type InputInfo,
} from "../../engine";
import { ACTUATION_SIZE, DOAS } from "../control/actuation";
import { signalInput } from "../shared/inputs";
import {
  MAX_DATAGRAM_BYTES,
  MAX_STREAMLINED_VALUES,
  RawEncoder,
  StreamlinedEncoder,
  valueSize,
} from "./udp-format";
import {
  byteParam,
  endpointText,
  formatParam,
  hostParam,
  portParam,
  udpBridge,
} from "./udp-common";
import { UdpSenderRun, type Lane, type Plan } from "./udp-sender-run";

/** Value types the sender writes (64-bit integers are read by the receiver, not written). */
const SEND_TYPES = ["f64", "f32", "i8", "i16", "i32", "u8", "u16", "u32"] as const;

export type Serializer = "vector" | "control" | "myo";

/**
 * MOSAIC picked the serializer from the type of the block feeding the sender: ControlAlgorithm →
 * one datagram per degree of actuation, Myo → the vector as scaled signed bytes; anything else
 * had no serializer (MOSAIC sent nothing), here the whole vector in one datagram.
 */
export function serializerFor(sourceType: string | undefined): Serializer {
  if (sourceType === "ControlAlgorithm") return "control";
  if (sourceType !== undefined && /^Myo/.test(sourceType)) return "myo";
  return "vector";
}

/** The type of the block behind an input, as the engine reports it. */
function sourceTypeOf(info: InputInfo): string | undefined {
  return info.type;
}

const params = z.strictObject({
  Host: hostParam("Destination: an IP address or host name (default 127.0.0.1)"),
  Port: portParam("Destination UDP port"),
  Format: formatParam,
  Serializer: z
    .enum(["auto", "vector", "control", "myo"])
    .default("auto")
    .describe(
      "Streamlined only. vector: each event in one datagram; control: one datagram per value " +
        "(count 1, f64, subcategory = the value's degree of actuation), as MOSAIC sent a " +
        "ControlAlgorithm's output; myo: the vector as signed bytes (value · 128, category 1, " +
        "subcategory 1), as MOSAIC sent a Myo's; auto: by the type of the input block, as MOSAIC " +
        "chose (ControlAlgorithm → control, Myo → myo, otherwise vector)",
    ),
  ValueType: z
    .enum(SEND_TYPES)
    .optional()
    .describe(
      "Streamlined only: type of the values on the wire (default f64; i8 for myo). Integers " +
        "are rounded and saturated at their range; NaN becomes 0",
    ),
  Category: byteParam(
    "Streamlined only: category byte (default 0 for vector, 1 for control and myo; MOSAIC: 0 EMG, 1 position control, 2 FMG)",
  ).optional(),
  Subcategory: byteParam(
    "Streamlined only: subcategory byte (default 0; 1 for myo); for control, the subcategory of the first value (value k gets Subcategory + k; by default a ControlAlgorithm's 11-value MOSAIC mapping sends its DOAs codes 0–8, 10, 11)",
  ).optional(),
  Subcategories: z
    .array(byteParam("subcategory"))
    .min(1)
    .max(MAX_STREAMLINED_VALUES)
    .optional()
    .describe(
      "Control only: the subcategory of each value (one per input value), e.g. MOSAIC's DOAs " +
        "enum values (0 ThumbFlexion … 8 WristPronationSupination, 10 ElbowFlexion, 11 ElbowExtension)",
    ),
  Scale: z
    .number()
    .optional()
    .describe("Values are multiplied by this before they are written (default 1; 128 for myo)"),
  Timestamp: z
    .enum(["event", "send"])
    .default("event")
    .describe(
      "Streamlined only: the timestamp written, the event's (pipeline clock, reproducible) or the " +
        "clock time at sending (what MOSAIC wrote)",
    ),
});

type Params = z.output<typeof params>;

/** A ControlAlgorithm's MOSAIC mapping: its 11 degrees of actuation (app/blocks/control/actuation.ts). */
function isMosaicActuation(sourceType: string | undefined, size: number): boolean {
  return sourceType === "ControlAlgorithm" && size === ACTUATION_SIZE;
}

/**
 * How input `index` of `inputs` is sent. With several inputs and no `Subcategory`, the vector
 * serializer of input i writes subcategory i, so a receiver can tell the streams apart.
 */
function plan(
  p: Params,
  size: number,
  sourceType: string | undefined,
  index = 0,
  inputs = 1,
): Plan {
  if (p.Format !== "streamlined") return rawPlan(p, p.Format, size);
  const serializer = p.Serializer === "auto" ? serializerFor(sourceType) : p.Serializer;
  if (serializer !== "control" && p.Subcategories !== undefined) {
    throw new BlockConfigError(
      `Subcategories applies to the control serializer (one datagram per value); the ${serializer} serializer sends one datagram per event: use Subcategory`,
      "Subcategories",
    );
  }
  if (serializer === "control") {
    return {
      serializer,
      type: p.ValueType ?? "f64",
      category: p.Category ?? 1,
      subcategories: controlSubcategories(p, size, sourceType),
      scale: p.Scale ?? 1,
    };
  }
  if (size > MAX_STREAMLINED_VALUES) {
    throw new BlockConfigError(
      `the input has ${size} values; a streamlined datagram holds at most ${MAX_STREAMLINED_VALUES} ` +
        "(its count is one byte): use Format f32 or f64, or select fewer channels",
      "Format",
    );
  }
  const myo = serializer === "myo";
  return {
    serializer,
    type: p.ValueType ?? (myo ? "i8" : "f64"),
    category: p.Category ?? (myo ? 1 : 0),
    subcategories: [p.Subcategory ?? (myo ? 1 : inputs > 1 ? index : 0)],
    scale: p.Scale ?? (myo ? 128 : 1),
  };
}

/** Format f32 / f64: bare vectors, which take none of the streamlined params. */
function rawPlan(p: Params, format: "f32" | "f64", size: number): Plan {
  const streamlinedOnly = ["Serializer", "ValueType", "Category", "Subcategory", "Subcategories"];
  for (const k of streamlinedOnly) {
    const v = p[k as keyof Params];
    if (v !== undefined && !(k === "Serializer" && (v === "auto" || v === "vector"))) {
      throw new BlockConfigError(
        `${k} applies to the streamlined format; Format ${format} sends bare ${format} vectors`,
        k,
      );
    }
  }
  const bytes = size * valueSize(format);
  if (bytes > MAX_DATAGRAM_BYTES) {
    throw new BlockConfigError(
      `the input has ${size} values (${bytes} bytes as ${format}), more than one UDP ` +
        `datagram holds (${MAX_DATAGRAM_BYTES} bytes)`,
      "Format",
    );
  }
  return {
    serializer: "vector",
    type: format,
    category: 0,
    subcategories: [],
    scale: p.Scale ?? 1,
  };
}

/** The control serializer: the subcategory of each of the `size` values. */
function controlSubcategories(p: Params, size: number, sourceType: string | undefined): number[] {
  if (p.Subcategories !== undefined) {
    if (p.Subcategories.length !== size) {
      throw new BlockConfigError(
        `Subcategories lists ${p.Subcategories.length} values but the input has ${size}: give one per value`,
        "Subcategories",
      );
    }
    return p.Subcategories;
  }
  if (isMosaicActuation(sourceType, size) && p.Subcategory === undefined) {
    // The MOSAIC mapping's degrees of actuation, sent with their DOAs codes as the original did.
    return DOAS.map((d) => d.code);
  }
  const first = p.Subcategory ?? 0;
  if (first + size - 1 > 255) {
    throw new BlockConfigError(
      `values 0…${size - 1} get subcategories ${first}…${first + size - 1}, past 255 (one byte): lower Subcategory or give Subcategories`,
      "Subcategory",
    );
  }
  return Array.from({ length: size }, (_, k) => first + k);
}

/** Every input's plan and encoder (the plans check the params against the inputs). */
function lanesFor(ctx: BlockContext, p: Params): Lane[] {
  const streamlined = p.Format === "streamlined";
  const n = ctx.inputs.length;
  return ctx.inputs.map((_, i) => {
    const input = signalInput(ctx, i);
    const pl = plan(p, input.size, sourceTypeOf(input.info), i, n);
    const perValue = pl.serializer === "control";
    return {
      plan: pl,
      size: input.size,
      perValue,
      sEnc: streamlined ? new StreamlinedEncoder(perValue ? 1 : input.size, pl.type) : undefined,
      rEnc: streamlined ? undefined : new RawEncoder(input.size, p.Format as "f32" | "f64"),
    };
  });
}

/** The serializers in use, as the status names them. */
function lanesText(ctx: BlockContext, p: Params, lanes: Lane[]): string {
  const laneText = (l: Lane): string =>
    `${l.plan.serializer} serializer, ${l.plan.type}, category ${l.plan.category}`;
  if (p.Format !== "streamlined") return `raw ${p.Format}`;
  if (lanes.length === 1) return laneText(lanes[0]!);
  return lanes.map((l, i) => `${ctx.inputs[i]!.source}: ${laneText(l)}`).join("; ");
}

export const UdpSender = defineBlock({
  type: "UdpSender",
  aliases: ["UDP_StreamlinedSender"],
  category: "Communication",
  summary: "Sends each input event as a UDP datagram: MOSAIC's streamlined format or raw vectors.",
  help:
    "Sends its input to a device, simulator or game engine over UDP (paper III-I, " +
    "UDP_StreamlinedSender). In the **streamlined** format (the default) every datagram is " +
    "`| count | type byte | category | subcategory | f64 timestamp | values | u16 counter |`, " +
    "little-endian, the counter counting every datagram this block sent (wrapping at 65535); " +
    "see docs/protocols.md. As in MOSAIC the serializer follows the input block's type: a " +
    "ControlAlgorithm's output goes as one datagram per degree of actuation (count 1, f64, " +
    "category 1, subcategory = the DoF), a Myo's as signed bytes (value · 128, category 1, " +
    "subcategory 1); anything else as one datagram per event with the declared Category and " +
    "Subcategory. `Serializer` overrides the choice, and the status names the serializer in " +
    "use. Formats **f32** and **f64** send bare " +
    "little-endian vectors, for peers that expect plain arrays. Nothing is sent in the browser " +
    "build (no sockets; the status says so). Every datagram that is not sent is counted and " +
    "shown, never fatal: the status reads `N datagrams sent, M not sent (the last reason)` and a " +
    "warning (at most every 2 s) gives the reason and the count so far — a host name that does " +
    "not resolve (each datagram until a new lookup succeeds; retried every 5 s), the queue of " +
    "the first milliseconds overflowing (256 datagrams wait while connecting), or a send that " +
    "fails (nothing listening: ECONNREFUSED). Several inputs (MOSAIC's sender subscribed to every input) are " +
    "sent to the same destination, each with the serializer of its own source (MOSAIC chose " +
    "one from the first input for all, and its vector serializer sent nothing), one counter " +
    "for all datagrams; vector inputs get subcategory = their position in Inputs unless " +
    "Subcategory says otherwise. MOSAIC's positional form is `[hostIP, port]`.",
  params,
  legacyParams(args) {
    if (args.length < 2) {
      throw new LegacyParamsError(
        `expected at least 2 arguments [hostIP, port] (as MOSAIC's UDP_StreamlinedSender), got ${args.length}`,
      );
    }
    const host = args[0]!.trim();
    if (host === "") throw new LegacyParamsError("the host (first argument) is empty");
    return { Host: host, Port: legacyInteger(args[1]!, "port", "Port") };
  },
  legacyForm: "[hostIP, port] (MOSAIC's UDP_StreamlinedSender; later arguments are ignored)",
  inputs: { min: 1, max: Infinity, labels: ["signal"] },
  outputs: [],
  views: ["label"],
  panel: "Destination, datagrams sent and send errors.",
  create(ctx, p) {
    const lanes = lanesFor(ctx, p);
    const settings = {
      host: p.Host,
      port: p.Port,
      dest: endpointText(p.Host, p.Port),
      what: lanesText(ctx, p, lanes),
      sendTime: p.Timestamp === "send",
      lanes,
    };
    return new UdpSenderRun(ctx, settings, udpBridge(ctx)).instance();
  },
});
