import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  legacyInteger,
  LegacyParamsError,
  vectorShape,
} from "../../engine";
import { pacedDevice, pacingTimer } from "./paced-device";
import {
  MUOVI_CHANNELS,
  MUOVI_HOST,
  MUOVI_PORT,
  MUOVI_RATE,
  SYNCSTATION_MUOVI_SLOTS,
} from "./muovi-protocol";
import { muoviProtocol, SyncStationLink } from "./muovi-link";
import { linkCountsText, nativeStreamSource } from "./stream-link";
import { gridParam } from "./electrode-arrays";
import { muoviMeta } from "./muovi-meta";
import { MUOVI_FULL_SCALE, slotOffsets } from "./muovi-protocol";

const params = z.strictObject({
  Probes: z
    .array(z.number().int().min(0).max(15))
    .min(1)
    .max(16)
    .refine((a) => new Set(a).size === a.length, "a probe is listed twice")
    .describe(
      "0-based indices of the probes on the SyncStation (the number on the probe minus 1), in " +
        "the order their channels appear in the output",
    ),
  Grid: gridParam(),
  Host: z
    .string()
    .trim()
    .min(1)
    .max(253)
    .default(MUOVI_HOST)
    .describe("The SyncStation's address (its Wi-Fi access point gives it 192.168.76.1)"),
  Port: z
    .number()
    .int()
    .min(1)
    .max(65535)
    .default(MUOVI_PORT)
    .describe("The SyncStation's TCP port"),
});

export const Muovi = defineBlock({
  type: "Muovi",
  category: "Devices",
  summary:
    "High-density EMG from OT Bioelettronica Muovi probes on a SyncStation: 32 channels per probe.",
  help:
    "OT Bioelettronica's Muovi probes (32 monopolar EMG channels each, 2 kHz) through a " +
    "SyncStation, as MOSAIC's Muovi block: this computer connects to the SyncStation " +
    `(TCP, ${MUOVI_HOST}:${MUOVI_PORT} on its Wi-Fi), sends the start command for the probes ` +
    "in `Probes` (EMG mode, 32 monopolar channels; CRC-8 checked by the SyncStation) and parses " +
    "its stream (int16 big-endian, 38 channels per probe in slot order, then the SyncStation's " +
    "6; protocol and sources in docs/protocols.md). **Without an input** it is its own source at " +
    "the probes' 2000 Hz: each TCP chunk's samples go out at once as one frame of vectors " +
    "[1, 32 × probes] (raw / 32768), stamped on the device's sample clock. **With a timer input** " +
    "(MOSAIC's form): every tick emits " +
    "one vector [1, 32 × probes] (the probes in the order of `Probes`, each probe's 32 EMG " +
    "channels in order), the average of 2000 / rate raw samples, in the original's units " +
    "(int16 / 32768); it repeats the last when none came and sends zeros while not streaming. " +
    "MOSAIC's positional form lists the probe indices: `Params: [0, 1]` is two probes, 64 " +
    "channels; a SyncStation has Muovi slots 0…3. A refused or lost connection, or 2 s without " +
    "data, is reported and retried (0.5 s doubling to 5 s); the stop command goes out when the " +
    "pipeline stops. The stream is aligned by the SyncStation's sample counter (its last " +
    "channel): malformed data is counted and skipped to the next whole sample, samples the " +
    "SyncStation skipped are counted. Never run against real hardware here: tested against " +
    "`mosaic simulate syncstation`. `mosaic run --simulate-devices` replaces it by an " +
    "EmgSimulator of the same shape and rate. Unavailable in the browser build (no TCP).",
  params,
  legacyParams(args) {
    const items = args.filter((a) => a.trim() !== "");
    if (items.length === 0) {
      throw new LegacyParamsError(
        "expected the probe indices, e.g. [0, 1] (MOSAIC's Muovi: 0-based, one per probe)",
        "Probes",
      );
    }
    return { Probes: items.map((a, i) => legacyInteger(a, `probe index ${i + 1}`, "Probes")) };
  },
  legacyForm: "[probeIndex, …] (0-based), e.g. [0, 1] for two probes (64 channels)",
  inputs: { min: 0, max: 1, labels: ["timer"] },
  outputs: ["emg"],
  eventLoop: true,
  views: ["scope", "spider", "heatmap"],
  panel:
    "Scope and heatmap of the channels; the link's state, samples, samples skipped by the SyncStation, malformed data, reconnections.",
  create(ctx, p) {
    const bad = p.Probes.find((s) => s >= SYNCSTATION_MUOVI_SLOTS);
    if (bad !== undefined) {
      throw new BlockConfigError(
        `probe index ${bad} is not a Muovi slot of the SyncStation (0…${SYNCSTATION_MUOVI_SLOTS - 1}; slots 4-5 are Muovi+/Sessantaquattro+, 6 and up Due+/Quattro+, which this block does not read)`,
        "Probes",
      );
    }
    let link: SyncStationLink | undefined;
    const actions = {
      counts: {
        label: "Counts",
        description:
          "Samples, samples the SyncStation skipped, malformed and truncated data, reconnections",
        run: () => linkCountsText(link?.counts),
      },
    };
    if (ctx.inputs.length === 0) {
      const offsets = slotOffsets(p.Probes);
      const o = { host: p.Host, port: p.Port, slots: p.Probes };
      const instance = nativeStreamSource(ctx, {
        rate: MUOVI_RATE,
        meta: muoviMeta(p.Probes, p.Grid),
        maxLead: 0.02,
        channels: MUOVI_CHANNELS * offsets.length,
        target: `the SyncStation at ${p.Host}:${p.Port}`,
        available: (c) => c.io.tcp !== undefined,
        open(c, ev) {
          link = new SyncStationLink(c, c.io.tcp!, o, ev);
          link.open();
          return link;
        },
        convert(raw, out, at) {
          for (let i = 0; i < offsets.length; i++) {
            const off = offsets[i]!;
            for (let j = 0; j < MUOVI_CHANNELS; j++) {
              out[at + i * MUOVI_CHANNELS + j] = raw[off + j]! / MUOVI_FULL_SCALE;
            }
          }
        },
      });
      return { ...instance, actions };
    }
    const rate = pacingTimer(ctx);
    const averageOver = Math.max(1, Math.floor(MUOVI_RATE / rate));
    const instance = pacedDevice(ctx, {
      device: "Muovi",
      target: `the Muovi SyncStation at ${p.Host}:${p.Port} (TCP)`,
      shape: vectorShape(MUOVI_CHANNELS * p.Probes.length),
      meta: muoviMeta(p.Probes, p.Grid),
      port: "emg",
      // Two of the SyncStation's packets (40 samples each, as public readers take them) wait at most.
      maxQueue: 2 * Math.ceil(40 / averageOver) + 1,
      protocol: muoviProtocol(p, averageOver, (l) => (link = l)),
    });
    return { ...instance, actions };
  },
});
