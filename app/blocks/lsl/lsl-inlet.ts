import { z } from "zod";
import { defineBlock, vectorShape } from "../../engine";
import { TextThrottle } from "../shared/text";
import { InletLink } from "./inlet-link";
import { bufferParam, lslBridge, nameParam, streamPredicate } from "./lsl-common";

/** Resolution params shared by both inlets. */
export const resolveParams = {
  Name: nameParam("Read the stream of this name"),
  Type: z.string().max(200).optional().describe("… of this content type (EEG, EMG, Markers, …)"),
  SourceId: z.string().max(200).optional().describe("… with this source id"),
  Predicate: z
    .string()
    .max(1000)
    .optional()
    .describe(
      "An XPath 1.0 predicate on the stream's description instead of Name/Type/SourceId, e.g. name='EMG' and hostname='lab-pc'",
    ),
  PollRate: z
    .number()
    .positive()
    .max(2000)
    .default(500)
    .describe("How often liblsl's buffer is read, Hz (latency vs. CPU)"),
  BufferSeconds: bufferParam,
  Recover: z
    .boolean()
    .default(true)
    .describe("Let liblsl reconnect to a stream that has a source id when it comes back"),
};

const params = z.strictObject({
  ...resolveParams,
  Channels: z
    .number()
    .int()
    .min(1)
    .max(65536)
    .describe("The stream's channel count (the output's width); other streams are refused"),
});
type Params = z.output<typeof params>;

export const LslInlet = defineBlock({
  type: "LslInlet",
  category: "Communication",
  summary: "Reads a Lab Streaming Layer stream: its samples as events on the pipeline clock.",
  help:
    "A source for anything that speaks the Lab Streaming Layer (an EEG amplifier's LSL app, " +
    "OpenViBE, pylsl, another MOSAIC's LslOutlet). It resolves the stream by `Name`, `Type`, " +
    "`SourceId` or an XPath `Predicate` (a continuous resolver: the pipeline never waits), opens " +
    "an inlet and emits the samples it pulls (every `PollRate`) as frames of [1, Channels] " +
    "events. Each sample keeps its own time: the sender's timestamp plus liblsl's clock offset " +
    "for that sender (`lsl_time_correction`, read every second) gives LSL time on this machine, " +
    "mapped onto the pipeline clock; samples pulled before the first offset is known are held " +
    "until it is. The status shows samples received, the latency (arrival minus timestamp) with " +
    "its jitter (standard deviation), the clock offset, and a stream lost (liblsl's lost error, " +
    "or a regular stream silent for 1 s or 20 periods) and recovered (liblsl reconnects to a " +
    "stream with a source id; others are resolved again). A stream with another channel count " +
    "or a string stream is refused with the reason. Uses liblsl through the host; unavailable in " +
    "the browser build (the status says so). Write `DesiredRate` as the stream's nominal rate: " +
    "downstream blocks (filters, windows) take it from there, and a stream of another nominal " +
    "rate is warned about. Meant for real time: under the virtual clock, " +
    "samples are stamped with LSL times shifted to the virtual start.",
  params,
  inputs: { min: 0, max: 0 },
  views: ["scope", "label"],
  panel: "Scope of the received values; the stream found, samples, latency, jitter and losses.",
  create(ctx, p: Params) {
    const predicate = streamPredicate(p);
    const out = ctx.output(vectorShape(p.Channels));
    const throttle = new TextThrottle(0.25);
    const link = new InletLink(ctx, {
      predicate,
      channels: p.Channels,
      acceptStrings: false,
      bufferS: p.BufferSeconds,
      recover: p.Recover,
      onSamples(n, values, _strings, times) {
        const f = out.frame(n);
        f.t.set(times.subarray(0, n));
        f.v.set(values.subarray(0, n * p.Channels));
        out.emit(f);
      },
    });
    // Every due tick in one call (a stall is not a skipped tick: the block is not behind).
    const timer = ctx.every(p.PollRate, (times, n) => {
      const now = times[n - 1]!;
      link.poll(now);
      if (throttle.due(now)) ctx.setText(link.text());
    });
    return {
      start() {
        const lsl = lslBridge(ctx);
        if (!lsl) return;
        if (!link.start(lsl)) {
          ctx.error(`LSL inlet: ${link.failure}`);
          ctx.setText(link.failure);
          return;
        }
        ctx.setText(link.text());
        timer.start();
      },
      stop() {
        timer.stop();
        link.close();
        ctx.setText(link.text());
      },
      dispose() {
        link.close();
      },
    };
  },
});
