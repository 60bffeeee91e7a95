import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  legacyInteger,
  LegacyParamsError,
  matrixShape,
} from "../../engine";
import { pacedDevice, pacingTimer } from "./paced-device";
import { MUOVI_CHANNELS, MUOVI_PROBE_PORT, MUOVI_RATE, muoviProbeProtocol } from "./muovi-protocol";

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
    "One Muovi probe connected directly (hold its button for 5 s and join the probe's Wi-Fi " +
    "network; the probe connects to this computer's TCP port `Port`), as MOSAIC's " +
    "MuoviSingleProbe: paced by one timer input, every tick emits the raw 2 kHz samples since the " +
    "previous tick as a matrix [2000 / rate, 32 × probes] (rows = samples, oldest first; the " +
    "integer part of 2000 / rate, as the original), or a vector [1, 32 × probes] when the timer " +
    "runs at 2 kHz, in mV. MOSAIC's positional form lists probe indices as Muovi's does " +
    "(`Params: [0]`). The probe's protocol comes in a later release: until then the block says " +
    "that the device is not reachable and sends zeros, and `mosaic run --simulate-devices` (or " +
    "the app's Simulate devices switch) replaces it by simulated EMG of the same shape and rate.",
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
  inputs: { min: 1, max: 1, labels: ["timer"] },
  outputs: ["emg"],
  eventLoop: true,
  views: ["scope", "heatmap"],
  panel: "Scope and heatmap of the channels; the link's state and samples received.",
  create(ctx, p) {
    const rate = pacingTimer(ctx);
    const rows = muoviRows(rate);
    if (rows < 1) {
      throw new BlockConfigError(
        `the timer ticks at ${rate} Hz, faster than the probe samples (${MUOVI_RATE} Hz): pace it at ${MUOVI_RATE} Hz or slower`,
      );
    }
    return pacedDevice(ctx, {
      device: "Muovi probe",
      target: `a Muovi probe connecting to TCP port ${p.Port} of this computer (over the probe's Wi-Fi)`,
      shape: matrixShape(rows, MUOVI_CHANNELS * p.Probes.length),
      port: "emg",
      protocol: muoviProbeProtocol(p, rows),
    });
  },
});
