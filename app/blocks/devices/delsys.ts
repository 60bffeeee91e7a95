import { z } from "zod";
import { defineBlock, vectorShape } from "../../engine";
import { delsysProtocol, TRIGNO_COMMAND_PORT, TRIGNO_SENSORS } from "./delsys-protocol";
import { pacedDevice, pacingTimer } from "./paced-device";

const params = z.strictObject({
  Sensors: z
    .number()
    .int()
    .min(1)
    .max(TRIGNO_SENSORS)
    .default(TRIGNO_SENSORS)
    .describe(
      "EMG sensors streamed (the output's width; the original took as many as were paired and " +
        "selected in its control panel)",
    ),
  Host: z
    .string()
    .trim()
    .min(1)
    .max(253)
    .default("127.0.0.1")
    .describe("The computer running Delsys' Trigno Control Utility (its SDK server)"),
});

export const Delsys = defineBlock({
  type: "Delsys",
  category: "Devices",
  summary: "EMG from a Delsys Trigno system: one channel per sensor, paced by a timer.",
  help:
    "A Delsys Trigno wireless EMG system, as MOSAIC's Delsys block: paced by one timer input, " +
    "every tick emits one vector [1, Sensors] with the newest EMG sample of each sensor (its " +
    "first EMG channel, in volts, as the original). The original took its sensors from its " +
    "control panel (scan, select, arm); here `Sensors` says how many, so the output's shape is " +
    "known when the pipeline loads. MOSAIC's form has no Params. The link (Delsys' Trigno SDK " +
    `over TCP, command port ${TRIGNO_COMMAND_PORT}) comes in a later release: until then the ` +
    "block says that the device is not reachable and sends zeros, and `mosaic run " +
    "--simulate-devices` (or the app's Simulate devices switch) replaces it by an EmgSimulator " +
    "of the same shape and rate.",
  params,
  legacyParams: () => ({}),
  legacyForm: "no Params (16 sensors)",
  inputs: { min: 1, max: 1, labels: ["timer"] },
  outputs: ["emg"],
  eventLoop: true,
  views: ["scope", "spider"],
  panel: "Scope of the sensors; the link's state and samples received.",
  create(ctx, p) {
    pacingTimer(ctx);
    return pacedDevice(ctx, {
      device: "Delsys Trigno",
      target: `the Trigno Control Utility at ${p.Host}:${TRIGNO_COMMAND_PORT} (Trigno SDK, TCP)`,
      shape: vectorShape(p.Sensors),
      port: "emg",
      protocol: delsysProtocol(p),
    });
  },
});
