import { z } from "zod";
import { defineBlock, LegacyParamsError, vectorShape } from "../../engine";
import { controlInput, describeControl } from "../control/actuation";
import { HannesHandRun } from "./hannes-hand-run";

const params = z.strictObject({
  Port: z
    .string()
    .trim()
    .min(1)
    .max(256)
    .default("COM50")
    .describe(
      "The serial port of IIT's Rehab Dongle: COM50 (the original's default, on Windows), " +
        "/dev/ttyACM0 or /dev/ttyUSB0 on Linux, /dev/cu.… on macOS",
    ),
  Device: z
    .string()
    .trim()
    .min(1)
    .max(256)
    .optional()
    .describe(
      "The Hannes to connect to, by the name the dongle's scan lists; default: the first found",
    ),
  Connect: z
    .boolean()
    .default(true)
    .describe(
      "Connect when the pipeline starts (scan, connect, configure, then stream); false: with the " +
        "connect action (the original's control-panel buttons)",
    ),
  Input: z
    .enum(["auto", "actuation", "prediction"])
    .default("auto")
    .describe(
      "What the control input carries: actuation (a ControlAlgorithm's MOSAIC output, 11 values " +
        "0–100) or prediction (MOSAIC's 12–15 predictions 0–1, mapped as DirectControl); auto: by " +
        "its width",
    ),
  Reconnect: z
    .number()
    .min(0)
    .max(3600)
    .default(1)
    .describe("Seconds between attempts to reopen the port after it failed or vanished (0: never)"),
});

export const HannesHand = defineBlock({
  type: "HannesHand",
  category: "Devices",
  summary:
    "Drives IIT's Hannes prosthetic hand through its Bluetooth Rehab Dongle on a serial port: hand, wrist and thumb references.",
  help:
    "MOSAIC's HannesHand (docs/protocols.md, Hannes): talks to the IIT Hannes hand through the " +
    "Bluetooth Rehab Dongle on a serial port (115200 Bd). When the pipeline starts (or on the " +
    "`connect` action with `Connect: false`) it does what the original's control panel did: " +
    "puts the dongle in command mode (`$$$`), scans (`scan`, up to 3 times) and connects to " +
    "`Device` or the first Hannes found (`con N`), checks the link (the hand must ACK " +
    "EnterCMDMode), activates the thumb and wrist joints, selects the control mode the original " +
    "used (UNITY) and switches the hand to stream mode. Then every control event sends one " +
    "SimultRefControl packet: hand open/close (the Middle finger's actuation, 0–100), wrist " +
    "pronation/supination −(PS − 50)·2 and thumb rotation −(TR − 50)·2 (−100–100) and wrist " +
    "flexion/extension (0–100). Packets are `%`, command, payload, `&`, CR, LF. The control input " +
    "is a ControlAlgorithm's MOSAIC output (11 degrees of actuation) or a plain prediction vector " +
    "(12–15 values, mapped as DirectControl). Output `reference` [1, 4] carries hand, wrist P/S, " +
    "wrist F/E and thumb as sent (also before the hand is connected). On stop it sends the " +
    "original's neutral pose (hand open, F/E 80, P/S and thumb 0), returns the hand to command " +
    "mode and disconnects the dongle (`$$$`, then `dct`: 2 s later on the disconnect action, at " +
    "once when the pipeline stops). The status says each step " +
    "and why one failed (no answer to scan, no Hannes found, no ACK). Needs the desktop app or " +
    "`mosaic run` (the browser build has no serial ports). MOSAIC's positional form is " +
    "`[COMport]`, optional.",
  params,
  legacyParams(args) {
    if (args.length > 1) {
      throw new LegacyParamsError(
        `expected [COMport] or no Params (MOSAIC's HannesHand), got ${args.length} arguments`,
        "Port",
      );
    }
    const port = (args[0] ?? "").trim();
    return port === "" ? {} : { Port: port };
  },
  legacyForm: "[COMport], e.g. [ COM50 ] (optional: COM50)",
  inputs: { min: 1, max: 1, labels: ["control"] },
  outputs: ["reference"],
  eventLoop: true,
  views: ["scope", "label"],
  panel:
    "Connection steps and state, devices found by the scan, the four references sent; connect, disconnect and scan buttons.",
  create(ctx, p) {
    const control = controlInput(ctx, 0, p.Input, "Input");
    if (ctx.declaredRate === undefined) ctx.setDesiredRate(ctx.inputs[0]?.rate ?? 0);
    const out = ctx.output(vectorShape(4), "reference");
    const run = new HannesHandRun(ctx, control, describeControl(control), out, {
      port: p.Port,
      reconnect: p.Reconnect,
      connect: p.Connect,
      device: p.Device,
    });
    return run.instance();
  },
});
