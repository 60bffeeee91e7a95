import { z } from "zod";
import { defineBlock, legacyInteger, LegacyParamsError, vectorShape } from "../../engine";
import {
  DLR_BAUD_RATE,
  DLR_DEFAULT_CHANNELS,
  DLR_MAX_CHANNELS,
  dlrAdcBtProtocol,
} from "./dlr-adcbt-protocol";
import { pacedDevice, pacingTimer } from "./paced-device";

const params = z.strictObject({
  Port: z
    .string()
    .trim()
    .max(256)
    .optional()
    .describe(
      "The serial port (COM5, /dev/rfcomm0, /dev/ttyUSB0); unset: choose it in the control panel, as in the original",
    ),
  Channels: z
    .number()
    .int()
    .min(1)
    .max(DLR_MAX_CHANNELS)
    .default(DLR_DEFAULT_CHANNELS)
    .describe("Analog channels read (the output's width)"),
});

export const DLR_ADCBT = defineBlock({
  type: "DLR_ADCBT",
  category: "Devices",
  summary: "Analog channels from the DLR ADC/BT converter over a serial port, paced by a timer.",
  help:
    "The DLR's ADC/BT analog-to-digital converter (e.g. force or FMG sensors) on a serial port " +
    `(Bluetooth SPP or USB, ${DLR_BAUD_RATE} Bd 8N1), as MOSAIC's DLR_ADCBT: when the pipeline ` +
    "starts it sends the board the channel count and the start command, then reads its frames " +
    "(`AA 7A`, the length byte, one big-endian 16-bit value per channel, `FF FF`; " +
    "docs/protocols.md). Paced by one timer input: every tick emits one vector [1, Channels] in " +
    "volts (5 · raw / 4000, as the original) with the oldest frame not yet emitted (the newest 15 " +
    "are kept; older ones are dropped and counted), the last one again when no frame came, and " +
    "zeros while the board is not streaming. Malformed frames (a wrong length byte, no `FF FF` " +
    "end) are dropped, counted in the status and the reader re-synchronises on the next start; " +
    "when the port disappears the status says `lost … reconnecting`, the port is reopened every " +
    "second and the board configured again. MOSAIC's positional form is " +
    `[COMport, numChannels] (both optional; ${DLR_DEFAULT_CHANNELS} channels by default). Needs the ` +
    "desktop app or `mosaic run` (the browser build has no serial ports: the status says so and " +
    "the rest of the pipeline runs). `mosaic simulate dlr-adcbt --port PATH` plays the board on " +
    "a serial device (one end of a socat pty pair); `mosaic run --simulate-devices` replaces " +
    "the block by a simulated signal of the same shape and rate.",
  params,
  legacyParams(args) {
    const port = (args[0] ?? "").trim();
    const n = (args[1] ?? "").trim();
    if (args.length > 2) {
      throw new LegacyParamsError(
        `expected [COMport, numChannels] (MOSAIC's DLR_ADCBT), got ${args.length} arguments`,
      );
    }
    return {
      ...(port !== "" ? { Port: port } : {}),
      ...(n !== "" ? { Channels: legacyInteger(n, "numChannels", "Channels") } : {}),
    };
  },
  legacyForm: `[COMport, numChannels], e.g. [COM5, 8] (both optional; ${DLR_DEFAULT_CHANNELS} channels)`,
  inputs: { min: 1, max: 1, labels: ["timer"] },
  outputs: ["analog"],
  eventLoop: true,
  views: ["scope"],
  panel:
    "Scope of the channels; the link's state, samples received, malformed frames and bytes skipped, reconnections.",
  create(ctx, p) {
    pacingTimer(ctx);
    const port = p.Port ? `serial port ${p.Port}` : "a serial port (none chosen: set Port)";
    return pacedDevice(ctx, {
      device: "DLR ADC/BT",
      target: `the DLR ADC/BT on ${port} at ${DLR_BAUD_RATE} Bd`,
      shape: vectorShape(p.Channels),
      port: "analog",
      protocol: dlrAdcBtProtocol(p),
    });
  },
});
