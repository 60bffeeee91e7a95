import { z } from "zod";
import { defineBlock, legacyInteger, LegacyParamsError, vectorShape } from "../../engine";
import { pacedDevice, pacingTimer } from "./paced-device";
import {
  MUOVI_CHANNELS,
  MUOVI_HOST,
  MUOVI_PORT,
  MUOVI_RATE,
  muoviProtocol,
} from "./muovi-protocol";

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
    "SyncStation, as MOSAIC's Muovi block: paced by one timer input, every tick emits one vector " +
    "[1, 32 × probes] (the probes in the order of `Probes`, each probe's 32 channels in order), " +
    "the average of the raw samples since the previous tick (2000 / rate of them), in the " +
    "original's units (int16 / 32768). MOSAIC's positional form lists the probe indices: " +
    "`Params: [0, 1]` is two probes, 64 channels. The SyncStation protocol (TCP to " +
    `${MUOVI_HOST}:${MUOVI_PORT}) comes in a later release: until then the block says that the ` +
    "device is not reachable and sends zeros, and `mosaic run --simulate-devices` (or the " +
    "app's Simulate devices switch) replaces it by an EmgSimulator of the same shape and rate.",
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
  inputs: { min: 1, max: 1, labels: ["timer"] },
  outputs: ["emg"],
  eventLoop: true,
  views: ["scope", "spider", "heatmap"],
  panel: "Scope and heatmap of the channels; the link's state and samples received.",
  create(ctx, p) {
    const rate = pacingTimer(ctx);
    return pacedDevice(ctx, {
      device: "Muovi",
      target: `the Muovi SyncStation at ${p.Host}:${p.Port} (TCP)`,
      shape: vectorShape(MUOVI_CHANNELS * p.Probes.length),
      port: "emg",
      protocol: muoviProtocol(p, Math.max(1, Math.floor(MUOVI_RATE / rate))),
    });
  },
});
