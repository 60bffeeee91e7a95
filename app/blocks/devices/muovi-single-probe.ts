import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  legacyInteger,
  LegacyParamsError,
  matrixShape,
} from "../../engine";
import { pacedDevice, pacingTimer } from "./paced-device";
import { MUOVI_CHANNELS, MUOVI_PROBE_PORT, MUOVI_RATE } from "./muovi-protocol";
import { muoviProbeProtocol, MuoviProbeLink } from "./muovi-link";
import { linkCountsText, nativeStreamSource } from "./stream-link";
import { gridParam } from "./electrode-arrays";
import { muoviMeta } from "./muovi-meta";
import { MUOVI_MV_PER_BIT } from "./muovi-protocol";

const params = z.strictObject({
  Probes: z
    .array(z.number().int().min(0).max(15))
    .min(1)
    .max(16)
    .refine((a) => new Set(a).size === a.length, "a probe is listed twice")
    .default([0])
    .describe(
      "0-based probe indices, as MOSAIC read them (one probe streams here; each index adds 32 " +
        "channels to the output)",
    ),
  Grid: gridParam(),
  Port: z
    .number()
    .int()
    .min(1)
    .max(65535)
    .default(MUOVI_PROBE_PORT)
    .describe("The local TCP port the probe connects to (on the probe's own Wi-Fi network)"),
});

/** Raw 2 kHz samples per tick: the rows of the output (1: a vector). */
export function muoviRows(rate: number): number {
  return Math.floor(MUOVI_RATE / rate);
}

export const MuoviSingleProbe = defineBlock({
  type: "MuoviSingleProbe",
  category: "Devices",
  summary:
    "EMG from one OT Bioelettronica Muovi probe over its own Wi-Fi: every raw sample since the last tick.",
  help:
    "One Muovi probe connected directly, as MOSAIC's MuoviSingleProbe: join the probe's Wi-Fi " +
    "(hold its button for 5 s); this computer listens on TCP port `Port` (every interface), the " +
    "probe connects to it and gets the start command byte (9: EMG mode, 32 monopolar channels, " +
    "2 kHz), then streams 38 int16 big-endian channels per sample (protocol and sources in " +
    "docs/protocols.md). **Without an input** it is its own source at 2000 Hz: each TCP chunk's " +
    "samples go out at once as one frame of vectors [1, 32 × probes] in mV, stamped on the " +
    "probe's sample clock. **With a timer input** (MOSAIC's form): every tick emits the raw 2 kHz " +
    "samples since " +
    "the previous tick as a matrix [2000 / rate, 32 × probes] (rows = samples, oldest first; the " +
    "integer part of 2000 / rate, as the original), or a vector [1, 32 × probes] when the timer " +
    "runs at 2 kHz, in mV (raw × 0.000286, 286.1 nV per bit); it repeats the last when none came " +
    "and sends zeros while not streaming. One probe streams here: it fills the first 32 columns " +
    "and any further index in `Probes` (MOSAIC's positional form, `Params: [0]`) gives 32 columns " +
    "of zeros. A probe that disconnects or is silent for 2 s is reported and the block waits for " +
    "it to connect again (a new connection replaces a dead one); the stop byte (8) goes out when " +
    "the pipeline stops. Malformed data is counted and skipped to the next whole sample (the " +
    "probe's sample counter, its last channel, keeps the alignment). Never run against real " +
    "hardware here: tested against `mosaic simulate muovi --connect HOST:PORT`. " +
    "`mosaic run --simulate-devices` replaces it by simulated EMG of the same shape and rate. " +
    "Unavailable in the browser build (no TCP).",
  params,
  legacyParams(args) {
    const items = args.filter((a) => a.trim() !== "");
    if (items.length === 0) {
      throw new LegacyParamsError(
        "expected the probe indices, e.g. [0] (MOSAIC's MuoviSingleProbe read them as Muovi does)",
        "Probes",
      );
    }
    return { Probes: items.map((a, i) => legacyInteger(a, `probe index ${i + 1}`, "Probes")) };
  },
  legacyForm: "[probeIndex, …] (0-based), e.g. [0]",
  inputs: { min: 0, max: 1, labels: ["timer"] },
  outputs: ["emg"],
  eventLoop: true,
  views: ["scope", "heatmap"],
  panel:
    "Scope and heatmap of the channels; the link's state, samples, samples the probe skipped, malformed data, reconnections.",
  create(ctx, p) {
    let link: MuoviProbeLink | undefined;
    const actions = {
      counts: {
        label: "Counts",
        description:
          "Samples, samples the probe skipped, malformed and truncated data, reconnections",
        run: () => linkCountsText(link?.counts),
      },
    };
    if (p.Probes.length > 1) {
      ctx.warn(
        `Muovi probe: one probe streams to this block; the ${p.Probes.length - 1} further index${p.Probes.length > 2 ? "es" : ""} in Probes give${p.Probes.length > 2 ? "" : "s"} columns of zeros`,
      );
    }
    if (ctx.inputs.length === 0) {
      const cols = MUOVI_CHANNELS * p.Probes.length;
      const instance = nativeStreamSource(ctx, {
        rate: MUOVI_RATE,
        meta: muoviMeta(p.Probes, p.Grid, "mV"),
        maxLead: 0.02,
        channels: cols,
        target: `a Muovi probe on TCP port ${p.Port}`,
        available: (c) => c.io.tcp?.listen !== undefined,
        open(c, ev) {
          link = new MuoviProbeLink(c, c.io.tcp!, { host: "0.0.0.0", port: p.Port }, ev);
          link.open();
          return link;
        },
        convert(raw, out, at) {
          for (let j = 0; j < MUOVI_CHANNELS; j++) out[at + j] = raw[j]! * MUOVI_MV_PER_BIT;
          out.fill(0, at + MUOVI_CHANNELS, at + cols);
        },
      });
      return { ...instance, actions };
    }
    if (p.Grid !== undefined) {
      throw new BlockConfigError(
        "Grid places a vector's channels on an electrode array: it applies without a timer input " +
          "(one vector per sample); the timer-paced form emits matrices of samples",
        "Grid",
      );
    }
    const rate = pacingTimer(ctx);
    const rows = muoviRows(rate);
    if (rows < 1) {
      throw new BlockConfigError(
        `the timer ticks at ${rate} Hz, faster than the probe samples (${MUOVI_RATE} Hz): pace it at ${MUOVI_RATE} Hz or slower`,
      );
    }
    const instance = pacedDevice(ctx, {
      device: "Muovi probe",
      target: `a Muovi probe connecting to TCP port ${p.Port} of this computer (over the probe's Wi-Fi)`,
      shape: matrixShape(rows, MUOVI_CHANNELS * p.Probes.length),
      port: "emg",
      // Two of the probe's packets (18 samples each, as public readers take them) wait at most.
      maxQueue: 2 * Math.ceil(18 / rows) + 1,
      protocol: muoviProbeProtocol(p, rows, (l) => (link = l)),
    });
    return { ...instance, actions };
  },
});
