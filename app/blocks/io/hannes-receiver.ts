import { z } from "zod";
import { defineBlock, LegacyParamsError, legacyInteger, vectorShape } from "../../engine";
import { timerInput } from "../shared/inputs";
import { HannesReceiverRun } from "./hannes-receiver-run";
import { portParam, udpBridge } from "./udp-common";

const params = z.strictObject({
  Port: portParam("The UDP port to listen on (the original listened on every address)"),
  Host: z
    .string()
    .trim()
    .min(1)
    .max(253)
    .regex(/^[A-Za-z0-9.:_%-]+$/, "expected an IP address or a host name")
    .default("0.0.0.0")
    .describe(
      "The local address to bind: 0.0.0.0 for every interface (the original's), 127.0.0.1 for this computer only",
    ),
  Channels: z
    .number()
    .int()
    .min(1)
    .max(1000)
    .default(6)
    .describe(
      "EMG values per datagram, each a little-endian u16 from byte 2 on, divided by 2¹⁶ (the " +
        "original decoded 6 whatever its numEMGs said)",
    ),
  MaxDelay: z
    .number()
    .int()
    .min(1)
    .max(100_000)
    .default(10)
    .describe(
      "With a timer input: samples kept waiting for ticks; older ones are dropped and counted " +
        "(the original's MAX_DELAY, 10)",
    ),
});

export const HannesReceiver = defineBlock({
  type: "HannesReceiver",
  category: "Devices",
  summary: "Receives EMG from IIT's Hannes over UDP: six 16-bit channels per datagram.",
  help:
    "MOSAIC's HannesReceiver (docs/protocols.md, Hannes): listens on a UDP port for the Hannes " +
    "EMG stream. A datagram holds a 2-byte header (not checked, as in the original) and then " +
    "`Channels` little-endian unsigned 16-bit values, each divided by 2¹⁶ (0 ≤ value < 1); " +
    "shorter datagrams are counted as malformed. With a timer input (MOSAIC's form) each tick " +
    "emits the oldest received sample, at most `MaxDelay` samples wait (older ones are dropped " +
    "and counted, as the original's MAX_DELAY), and a tick without a new sample repeats the last " +
    "one (counted; zeros before the first; the original sent zeros, and zeros again on every " +
    "tick that dropped samples). Without an input every datagram is one event at its arrival. " +
    "The socket opens when the pipeline starts (the original waited for its panel's Connect). " +
    "MOSAIC's positional form is `[udpPort, numEMGs]`.",
  params,
  legacyParams(args) {
    if (args.length !== 2) {
      throw new LegacyParamsError(
        `expected [udpPort, numEMGs] (MOSAIC's HannesReceiver), got ${args.length} argument${args.length === 1 ? "" : "s"}`,
      );
    }
    return {
      Port: legacyInteger(args[0]!, "port", "Port"),
      Channels: legacyInteger(args[1]!, "numEMGs", "Channels"),
    };
  },
  legacyForm: "[udpPort, numEMGs], e.g. [11000, 6]",
  inputs: { min: 0, max: 1, labels: ["timer"] },
  eventLoop: true,
  views: ["scope", "label"],
  panel: "The EMG values; datagrams received, samples dropped and repeated.",
  create(ctx, p) {
    const paced = ctx.inputs.length > 0;
    if (paced) timerInput(ctx, 0);
    const out = ctx.output(vectorShape(p.Channels));
    const run = new HannesReceiverRun(ctx, udpBridge(ctx), out, {
      host: p.Host,
      port: p.Port,
      channels: p.Channels,
      maxDelay: p.MaxDelay,
      paced,
    });
    return run.instance();
  },
});
