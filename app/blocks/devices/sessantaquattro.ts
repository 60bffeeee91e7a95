import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  errorMessage,
  type ElectrodeGrid,
  type PortMeta,
} from "../../engine";
import { electrodeGrid, gridParam } from "./electrode-arrays";
import {
  mvPerBit,
  SESSANTAQUATTRO_CHANNELS,
  SESSANTAQUATTRO_MODELS,
  SESSANTAQUATTRO_MODES,
  SESSANTAQUATTRO_PORT,
  SESSANTAQUATTRO_RATES,
  wireLayout,
  type SessantaquattroConfig,
} from "./sessantaquattro-protocol";
import { SessantaquattroLink, sessantaquattroTarget } from "./sessantaquattro-link";
import { linkCountsText, nativeStreamSource } from "./stream-link";

const literals = <T extends number>(values: readonly T[]) =>
  z.union(values.map((v) => z.literal(v)) as unknown as [z.ZodLiteral<T>, z.ZodLiteral<T>]);

const params = z.strictObject({
  Model: z
    .enum(SESSANTAQUATTRO_MODELS)
    .default("Sessantaquattro+")
    .describe(
      "Sessantaquattro (2 AUX + 2 accessory channels after the bioelectrical ones) or " +
        "Sessantaquattro+ (2 AUX, 4 IMU quaternion channels, 2 accessory)",
    ),
  Host: z
    .string()
    .trim()
    .min(1)
    .max(253)
    .regex(/^[A-Za-z0-9.:_%-]+$/, "expected a local IP address or a host name")
    .default("0.0.0.0")
    .describe("The local address to listen on (0.0.0.0: every interface)"),
  Port: z
    .number()
    .int()
    .min(1)
    .max(65535)
    .default(SESSANTAQUATTRO_PORT)
    .describe("The local TCP port the device connects to (its default is 45454)"),
  Mode: z
    .enum(SESSANTAQUATTRO_MODES)
    .default("monopolar")
    .describe(
      "Detection mode (MODE): monopolar; bipolar (AD8x1SP adapter: half the channels); " +
        "differential (consecutive inputs within groups of 32)",
    ),
  Channels: literals(SESSANTAQUATTRO_CHANNELS)
    .default(64)
    .describe("Bioelectrical channels (NCH): 8, 16, 32 or 64 (bipolar mode streams half)"),
  Rate: literals(SESSANTAQUATTRO_RATES)
    .default(2000)
    .describe("Sampling rate (FSAMP), Hz: 500, 1000, 2000 or 4000 (the block's output rate)"),
  HighRes: z
    .boolean()
    .default(false)
    .describe("HRES: 24-bit samples (e.g. DC-coupled EEG); false: 16-bit"),
  HPF: z
    .boolean()
    .default(true)
    .describe("The device's high-pass filter (cut-off Rate / 190 Hz, 10.5 Hz at 2000 Hz)"),
  Unit: z
    .enum(["mV", "raw"])
    .default("mV")
    .describe(
      "mV (bioelectrical: 286 nV per bit; AUX: 146.48 µV per bit at 16 bits, 572.2 nV at " +
        "24; IMU and accessory channels as sent) or the raw integers",
    ),
  Grid: gridParam(),
  Extras: z
    .boolean()
    .default(true)
    .describe(
      "Also output the AUX, IMU (Sessantaquattro+) and accessory channels (buffer, sample " +
        "counter) after the bioelectrical ones; false: the bioelectrical channels only",
    ),
});

type Params = z.output<typeof params>;

/** The device's configuration from the params. */
export function sessantaquattroConfig(p: Params): SessantaquattroConfig {
  return {
    model: p.Model,
    mode: p.Mode,
    channels: p.Channels,
    rate: p.Rate,
    highRes: p.HighRes,
    hpf: p.HPF,
  };
}

/** The output channels: their names and mV per bit (1 when raw). */
export function sessantaquattroOutputs(p: Params): { name: string; scale: number }[] {
  return wireLayout(sessantaquattroConfig(p))
    .filter((c) => p.Extras || c.kind === "bio")
    .map((c) => ({ name: c.name, scale: p.Unit === "raw" ? 1 : mvPerBit(c.kind, p.HighRes) }));
}

/** The unit of an output channel, for the `channels` action. */
function unitOf(name: string, p: Params): string {
  if (p.Unit === "raw") return p.HighRes ? "int24" : "int16";
  return /^(EMG|AUX)/.test(name) ? "mV" : "as sent";
}

/** Labels (the channels' names), the unit when every channel has the same, and the array. */
function outputMeta(outs: readonly { name: string }[], p: Params): PortMeta {
  let grid: ElectrodeGrid | undefined;
  try {
    grid = electrodeGrid(p.Grid, outs.length);
  } catch (e) {
    throw new BlockConfigError(errorMessage(e), "Grid");
  }
  const units = new Set(outs.map((c) => unitOf(c.name, p)));
  const unit = units.size === 1 ? [...units][0]! : undefined;
  return {
    labels: outs.map((c) => c.name),
    ...(unit !== undefined && unit !== "as sent" ? { unit } : {}),
    ...(grid ? { grid } : {}),
  };
}

export const Sessantaquattro = defineBlock({
  type: "Sessantaquattro",
  category: "Devices",
  summary:
    "High-density EMG/EEG from an OT Bioelettronica Sessantaquattro(+) over Wi-Fi: up to 64 channels at 500–4000 Hz.",
  help:
    "OT Bioelettronica's Sessantaquattro and Sessantaquattro+ (8, 16, 32 or 64 bioelectrical " +
    "channels, 2 AUX; the + adds an IMU) over their TCP protocol: this computer listens on " +
    '`Port` (45454) and the device connects to it (set its "Server IP address" on its web ' +
    "page, or join its Wi-Fi); each connection gets the 16-bit command word with GO set (Mode, " +
    "Channels, Rate, HighRes, HPF), then the device streams per sample every channel as a " +
    "big-endian integer of 16 bits (24 with HighRes): the bioelectrical channels, AUX 1-2, on " +
    "the + IMU W, X, Y, Z, then the accessory channels (buffer, sample counter; protocol and " +
    "sources in docs/protocols.md, section OT Bioelettronica Sessantaquattro). It is its own " +
    "source at `Rate`: each TCP chunk's samples go out at once as one frame of vectors " +
    "[1, channels] in mV (`Unit: raw` for the integers; `Extras: false` for the bioelectrical " +
    "channels only), stamped on the device's sample clock. The `channels` action names every " +
    "output channel. A device that disconnects or is silent for 2 s is reported and the block " +
    "waits for it to connect again; a port that cannot be listened on (taken by another " +
    "program) is said and tried again (0.5 s doubling to 5 s); the command word with GO clear " +
    "goes out when the pipeline stops. The stream is aligned by the device's sample counter " +
    "(the last channel): malformed data is counted and skipped to the next whole sample, " +
    "samples the device skipped are counted. The protocol allows 4000 Hz only with fewer " +
    "channels (it does not say how many). The original MOSAIC had no Sessantaquattro block. " +
    "Never run against real hardware here: tested against `mosaic simulate sessantaquattro " +
    "--connect HOST:PORT`. `mosaic run --simulate-devices` replaces it by an EmgSimulator of " +
    "the same shape and rate. Unavailable in the browser build (no TCP).",
  params,
  inputs: { min: 0, max: 0 },
  outputs: ["emg"],
  eventLoop: true,
  views: ["scope", "heatmap"],
  panel:
    "Scope and heatmap of the channels; the link's state, samples, samples skipped by the device, malformed data, reconnections.",
  create(ctx, p) {
    const config = sessantaquattroConfig(p);
    const outs = sessantaquattroOutputs(p);
    const scale = Float64Array.from(outs, (c) => c.scale);
    if (p.Rate === 4000 && p.Channels === 64 && p.Mode !== "bipolar") {
      ctx.warn(
        "Sessantaquattro: the protocol allows 4000 Hz only with a reduced number of channels; with 64 the device may not stream (choose fewer Channels or a lower Rate)",
      );
    }
    let link: SessantaquattroLink | undefined;
    const actions = {
      channels: {
        label: "Channels",
        description: "What each output channel carries, and its unit",
        run: () =>
          outs.map((c, i) => `channel ${i + 1}: ${c.name} (${unitOf(c.name, p)})`).join("; "),
      },
      counts: {
        label: "Counts",
        description:
          "Samples, samples the device skipped, malformed and truncated data, reconnections",
        run: () => linkCountsText(link?.counts),
      },
    };
    const o = { host: p.Host, port: p.Port, config };
    const instance = nativeStreamSource<Int32Array>(ctx, {
      rate: p.Rate,
      meta: outputMeta(outs, p),
      maxLead: 0.05,
      channels: outs.length,
      target: sessantaquattroTarget(p.Model, p.Port),
      available: (c) => c.io.tcp?.listen !== undefined,
      open(c, ev) {
        link = new SessantaquattroLink(c, c.io.tcp!, o, ev);
        link.open();
        return link;
      },
      convert(raw, out, at) {
        for (let j = 0; j < scale.length; j++) out[at + j] = raw[j]! * scale[j]!;
      },
    });
    return { ...instance, actions };
  },
});
