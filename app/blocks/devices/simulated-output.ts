import { z } from "zod";
import { defineBlock, shapeSize } from "../../engine";
import { plural, TextThrottle } from "../shared/text";
import { MAX_ITEMS } from "../shared/limits";

const COUNTS = ["events", "values"] as const;

export const SimulatedOutput = defineBlock({
  type: "SimulatedOutput",
  category: "Devices",
  summary:
    "Stands in for an output device when devices are simulated: counts what it would have sent.",
  help:
    "What `mosaic run --simulate-devices` (and the app's Simulate devices switch) puts in place " +
    "of a block that sends to a device or over the network (BlenderArm, HannesHand, HannesGUI, " +
    "UdpSender, a ROS publisher, a SerialPort that only writes): it takes the same inputs, sends " +
    "nothing, and counts what the device block would have sent, `Unit`s of one per event of " +
    "each input, or one per value (`Count: values`, for a sender that sent one datagram per " +
    "value; `Count` may say it per input). Its status says what it replaces and how much was not sent, e.g. “simulated " +
    "BlenderArm → localhost:3334: 250 datagrams not sent”.",
  params: z.strictObject({
    Device: z.string().min(1).max(200).describe("The block type it stands in for, e.g. BlenderArm"),
    Destination: z
      .string()
      .max(500)
      .optional()
      .describe(
        "Where that block would have sent, e.g. localhost:3334, COM50, ws://localhost:9090 /topic",
      ),
    Unit: z
      .enum(["datagram", "message", "command", "frame", "event"])
      .default("event")
      .describe("What the device block sends, for the status text"),
    Count: z
      .union([z.enum(COUNTS), z.array(z.enum(COUNTS)).min(1).max(MAX_ITEMS)])
      .default("events")
      .describe(
        "events: one unit per input event; values: one per value of each event; a list: one of " +
          "these per input, in the order of Inputs (the others count events)",
      ),
  }),
  inputs: { min: 1, max: Infinity },
  outputs: [],
  views: ["label"],
  panel: "What it stands in for and how much was not sent.",
  create(ctx, p) {
    const perEvent = ctx.inputs.map((inp, i) => {
      const count = typeof p.Count === "string" ? p.Count : (p.Count[i] ?? "events");
      return count === "values" && inp.shape !== null ? shapeSize(inp.shape) : 1;
    });
    let units = 0;
    const throttle = new TextThrottle();
    const to = p.Destination ? ` → ${p.Destination}` : "";
    const describe = (): void =>
      ctx.setText(`simulated ${p.Device}${to}: ${plural(units, p.Unit)} not sent`);
    describe();
    return {
      process(f, port) {
        const n = f.n;
        units += n * (perEvent[port] ?? 1);
        if (n > 0 && throttle.due(f.t[n - 1]!)) describe();
      },
      stop() {
        describe();
      },
      reset() {
        units = 0;
        throttle.reset();
        describe();
      },
    };
  },
});
