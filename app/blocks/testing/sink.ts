import { z } from "zod";
import { defineBlock } from "../../engine";
import { TextThrottle } from "../shared/text";

export const Sink = defineBlock({
  type: "Sink",
  category: "Testing",
  summary: "Discards its inputs and counts their events (a stand-in for a device output).",
  help:
    "Accepts any number of inputs of any shape and throws their events away, counting them; its " +
    "status text shows the count. It stands in for a device output (UDP, serial, a prosthesis) " +
    "in tests and benchmarks, so a pipeline's processing runs without hardware.",
  params: z.strictObject({}),
  legacyParams: () => ({}),
  legacyForm: "no params",
  inputs: { min: 1, max: Infinity },
  outputs: [],
  views: ["label"],
  panel: "Number of events received.",
  create(ctx) {
    let events = 0;
    const throttle = new TextThrottle();
    const describe = () => ctx.setText(`${events} event${events === 1 ? "" : "s"} received`);
    describe();
    return {
      process(f) {
        events += f.n;
        if (f.n > 0 && throttle.due(f.t[f.n - 1]!)) describe();
      },
      stop() {
        describe();
      },
      reset() {
        events = 0;
        throttle.reset();
        describe();
      },
    };
  },
});
