import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  errorMessage,
  type ElectrodeGrid,
  type PortMeta,
} from "../../engine";
import {
  ANALOG_OUT_GAINS,
  AUX_MV_PER_BIT,
  CONFIGURED_INPUTS,
  connectorChannels,
  connectorOffset,
  CONNECTORS,
  DEFAULT_INPUT,
  DETECTION,
  EMG_MV_PER_BIT,
  HIGH_PASS,
  LOW_PASS,
  nchFor,
  QUATTROCENTO_CHANNEL_COUNTS,
  QUATTROCENTO_HOST,
  QUATTROCENTO_PORT,
  QUATTROCENTO_RATES,
  SIDES,
  type Connector,
  type InputSettings,
  type QuattrocentoConfig,
} from "./quattrocento-protocol";
import { QuattrocentoLink, quattrocentoTarget } from "./quattrocento-link";
import { linkCountsText, nativeStreamSource } from "./stream-link";
import { electrodeGrid, gridParam, type GridParam } from "./electrode-arrays";

const literals = <T extends number>(values: readonly T[]) =>
  z.union(values.map((v) => z.literal(v)) as unknown as [z.ZodLiteral<T>, z.ZodLiteral<T>]);

const inputFields = {
  HighPass: literals(HIGH_PASS).describe("High-pass filter, Hz: 0.7, 10, 100 or 200"),
  LowPass: literals(LOW_PASS).describe("Low-pass filter, Hz: 130, 500, 900 or 4400"),
  Mode: z.enum(DETECTION).describe("Detection mode: monopolar, differential or bipolar"),
};

const inputSettings = z.strictObject({
  ...inputFields,
  Muscle: z
    .number()
    .int()
    .min(0)
    .max(64)
    .describe("Muscle index of OTB's list (0: not defined, 64: not a muscle)"),
  Sensor: z
    .number()
    .int()
    .min(0)
    .max(23)
    .describe("Sensor index of OTB's list (0: not defined, e.g. 12: 64-electrode grid, 8 mm)"),
  Adapter: z
    .number()
    .int()
    .min(0)
    .max(6)
    .describe("Adapter index of OTB's list (0: not defined, 4: AD1x64)"),
  Side: z.enum(SIDES).describe("Side of the body: undefined, left, right or none"),
});

const params = z.strictObject({
  Host: z
    .string()
    .trim()
    .min(1)
    .max(253)
    .regex(/^[A-Za-z0-9.:_%-]+$/, "expected an IP address or a host name")
    .default(QUATTROCENTO_HOST)
    .describe("The Quattrocento's address (its default is 169.254.1.10)"),
  Port: z
    .number()
    .int()
    .min(1)
    .max(65535)
    .default(QUATTROCENTO_PORT)
    .describe("The Quattrocento's TCP port"),
  Rate: literals(QUATTROCENTO_RATES)
    .default(2048)
    .describe("Sampling rate, Hz: 512, 2048, 5120 or 10240 (the block's output rate)"),
  Decimator: z
    .boolean()
    .default(true)
    .describe(
      "Sample at 10240 Hz and send one sample in 2, 5 or 20 (OTB's example's choice); false: sample at Rate",
    ),
  Connectors: z
    .array(z.enum(CONNECTORS))
    .min(1)
    .max(CONNECTORS.length)
    .refine((a) => new Set(a).size === a.length, "a connector is listed twice")
    .default(["MULTIPLE IN1"])
    .describe(
      "The connectors whose channels are output, in this order: IN1…IN8 (16 channels each), " +
        "MULTIPLE IN1…MULTIPLE IN4 (64 each), AUX IN (16)",
    ),
  Channels: literals(QUATTROCENTO_CHANNEL_COUNTS)
    .optional()
    .describe(
      "Channels the device streams per sample (NCH): 120, 216, 312 or 408; default the smallest " +
        "that carries every connector listed",
    ),
  Select: z
    .array(z.number().int().min(1).max(400))
    .min(1)
    .max(400)
    .optional()
    .describe(
      "1-based channel numbers, within the listed connectors' channels in order, to output " +
        "(in this order); default all of them",
    ),
  Grid: gridParam(),
  Unit: z
    .enum(["mV", "raw"])
    .default("mV")
    .describe("mV (inputs: raw · 5/2¹⁶/150 V; AUX IN: raw · 5/2¹⁶/0.5 V) or the raw int16"),
  HighPass: inputFields.HighPass.default(10).describe(
    "High-pass filter of every input, Hz (0.7, 10, 100, 200); Settings can override per input",
  ),
  LowPass: inputFields.LowPass.default(500).describe(
    "Low-pass filter of every input, Hz (130, 500, 900, 4400); Settings can override per input",
  ),
  Mode: inputFields.Mode.default("monopolar").describe(
    "Detection mode of every input (monopolar, differential, bipolar); Settings can override per input",
  ),
  Settings: z
    .partialRecord(
      z.enum(CONFIGURED_INPUTS as [Connector, ...Connector[]]),
      inputSettings.partial(),
    )
    .default({})
    .describe(
      "Per-input settings sent to the device, by connector (IN1…IN8, MULTIPLE IN1…IN4): " +
        "HighPass, LowPass, Mode, Muscle, Sensor, Adapter, Side",
    ),
  AnalogOut: z
    .strictObject({
      Source: z.enum(CONNECTORS).describe("The connector routed to the ANALOG OUT BNC"),
      Channel: z
        .number()
        .int()
        .min(1)
        .max(64)
        .describe("Its channel (1-based; the device counts from 0)"),
      Gain: literals(ANALOG_OUT_GAINS).describe("Analog output gain: 1, 2, 4 or 16"),
    })
    .default({ Source: "IN1", Channel: 1, Gain: 1 })
    .describe("The analog output (rear BNC)"),
  Trigger: z
    .boolean()
    .default(false)
    .describe("REC_ON: mark the acquisition on the Trigger OUT (to start other instruments)"),
});

type Params = z.output<typeof params>;

/** One output channel: where it is on the wire, its scale and its name. */
interface OutputChannel {
  wire: number;
  scale: number;
  name: string;
}

/** The channels of the listed connectors in order, then picked by Select (1-based). */
function outputChannels(p: Params, nch: number): OutputChannel[] {
  const all: OutputChannel[] = [];
  for (const c of p.Connectors) {
    const off = connectorOffset(c, nch);
    const perBit = c === "AUX IN" ? AUX_MV_PER_BIT : EMG_MV_PER_BIT;
    for (let i = 0; i < connectorChannels(c); i++) {
      all.push({ wire: off + i, scale: p.Unit === "raw" ? 1 : perBit, name: `${c}/${i + 1}` });
    }
  }
  if (!p.Select) return all;
  const bad = p.Select.find((s) => s > all.length);
  if (bad !== undefined) {
    throw new BlockConfigError(
      `channel ${bad} is not among the ${all.length} channels of ${p.Connectors.join(", ")}`,
      "Select",
    );
  }
  return p.Select.map((s) => all[s - 1]!);
}

/** The NCH code: Channels, or the smallest carrying every connector. */
function nchOf(p: Params): number {
  const needed = nchFor(p.Connectors);
  if (p.Channels === undefined) return needed;
  const nch = QUATTROCENTO_CHANNEL_COUNTS.indexOf(p.Channels);
  if (nch < needed) {
    throw new BlockConfigError(
      `${p.Channels} channels do not carry ${p.Connectors.join(", ")}: they need ${QUATTROCENTO_CHANNEL_COUNTS[needed]} or more`,
      "Channels",
    );
  }
  return nch;
}

/** The device's configuration from the params. */
export function quattrocentoConfig(p: Params, nch: number): QuattrocentoConfig {
  const inputs: InputSettings[] = CONFIGURED_INPUTS.map((c) => {
    const s = p.Settings[c] ?? {};
    return {
      ...DEFAULT_INPUT,
      highPass: s.HighPass ?? p.HighPass,
      lowPass: s.LowPass ?? p.LowPass,
      mode: s.Mode ?? p.Mode,
      muscle: s.Muscle ?? 0,
      sensor: s.Sensor ?? 0,
      adapter: s.Adapter ?? 0,
      side: s.Side ?? "undefined",
    };
  });
  return {
    rate: p.Rate,
    nch,
    decimator: p.Decimator,
    recording: p.Trigger,
    analogOut: {
      source: p.AnalogOut.Source,
      channel: p.AnalogOut.Channel - 1,
      gain: p.AnalogOut.Gain,
    },
    inputs,
  };
}

export const Quattrocento = defineBlock({
  type: "Quattrocento",
  category: "Devices",
  summary:
    "High-density EMG from an OT Bioelettronica Quattrocento over TCP: up to 384 channels + 16 AUX at 512–10240 Hz.",
  help:
    "OT Bioelettronica's Quattrocento amplifier (8 IN connectors of 16 channels, 4 MULTIPLE IN " +
    "of 64, 16 AUX IN) over its TCP protocol: this computer connects to the device " +
    `(${QUATTROCENTO_HOST}:${QUATTROCENTO_PORT} by default, on its Ethernet port), sends the ` +
    "40-byte configuration command (rate, channel count, per-input filters and detection mode, " +
    "CRC-8) with acquisition on and parses the stream: per sample 120, 216, 312 or 408 int16 " +
    "little-endian channels (the active INs, MULTIPLE INs, AUX IN, 8 accessory channels; protocol " +
    "and sources in docs/protocols.md, section OT Bioelettronica Quattrocento). It is its own " +
    "source at `Rate`: each TCP chunk's samples go out at once as one frame of vectors " +
    "[1, channels] (the `Connectors`' channels in order, or those picked by `Select`), in mV " +
    "(`Unit: raw` for the int16), stamped on the device's sample clock. The `channels` action " +
    "names every output channel (`MULTIPLE IN1/12`). A refused or lost connection, or 2 s " +
    "without data, is reported and retried (0.5 s doubling to 5 s); the command with acquisition " +
    "off goes out when the pipeline stops. The stream is aligned by the device's sample counter " +
    "(the first accessory channel): malformed data is counted and skipped to the next whole " +
    "sample, samples the device skipped are counted. The original MOSAIC had no Quattrocento " +
    "block. Never run against real hardware here: tested against `mosaic simulate quattrocento`. " +
    "`mosaic run --simulate-devices` replaces it by an EmgSimulator of the same shape and rate. " +
    "Unavailable in the browser build (no TCP).",
  params,
  inputs: { min: 0, max: 0 },
  outputs: ["emg"],
  eventLoop: true,
  views: ["scope", "heatmap"],
  panel:
    "Scope and heatmap of the channels; the link's state, samples, samples skipped by the device, malformed data, reconnections.",
  create(ctx, p) {
    const nch = nchOf(p);
    const chans = outputChannels(p, nch);
    const config = quattrocentoConfig(p, nch);
    const wire = Int32Array.from(chans, (c) => c.wire);
    const scale = Float64Array.from(chans, (c) => c.scale);
    const unit = p.Unit === "raw" ? "int16" : "mV";
    let link: QuattrocentoLink | undefined;
    const actions = {
      channels: {
        label: "Channels",
        description: "Which connector and channel each output channel carries",
        run: () => chans.map((c, i) => `channel ${i + 1}: ${c.name} (${unit})`).join("; "),
      },
      counts: {
        label: "Counts",
        description:
          "Samples, samples the device skipped, malformed and truncated data, reconnections",
        run: () => linkCountsText(link?.counts),
      },
    };
    const o = { host: p.Host, port: p.Port, config, outputs: chans.length };
    const instance = nativeStreamSource(ctx, {
      rate: p.Rate,
      meta: channelMeta(chans, unit, p.Grid),
      maxLead: 0.05,
      channels: chans.length,
      target: quattrocentoTarget(p.Host, p.Port),
      available: (c) => c.io.tcp !== undefined,
      open(c, ev) {
        link = new QuattrocentoLink(c, c.io.tcp!, o, ev);
        link.open();
        return link;
      },
      convert(raw, out, at) {
        for (let j = 0; j < wire.length; j++) out[at + j] = raw[wire[j]!]! * scale[j]!;
      },
    });
    return { ...instance, actions };
  },
});

/** Labels "IN1/3" (the channels action's names), the unit, and the electrode array if given. */
function channelMeta(
  chans: readonly { name: string }[],
  unit: string,
  grid: GridParam | undefined,
): PortMeta {
  let g: ElectrodeGrid | undefined;
  try {
    g = electrodeGrid(grid, chans.length);
  } catch (e) {
    throw new BlockConfigError(errorMessage(e), "Grid");
  }
  return { labels: chans.map((c) => c.name), unit, ...(g ? { grid: g } : {}) };
}
