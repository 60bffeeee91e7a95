import { z } from "zod";
import { defineBlock, EMPTY_SHAPE } from "../../engine";

export const ScheduledTimer = defineBlock({
  type: "ScheduledTimer",
  category: "Timing",
  summary: "Paces the pipeline: emits a tick at DesiredRate from the high-resolution scheduler.",
  help:
    "The primary timing source (paper III-D). Ticks come from one high-resolution clock; a tick " +
    "whose deadline has already passed by a whole period is skipped and counted as missed rather " +
    "than fired late in a burst. Ticks carry no values; their timestamps are the times they fired " +
    "(virtual time under the virtual clock). Right-click actions start and stop it; with " +
    "`Autostart: false` it waits for the start action.",
  params: z.strictObject({
    Autostart: z.boolean().default(true).describe("Start ticking when the pipeline starts"),
  }),
  legacyParams: () => ({}),
  legacyForm: "no params: `{ Type: ScheduledTimer, DesiredRate: 200 }`",
  inputs: { min: 0, max: 0 },
  timer: true,
  views: ["label"],
  panel: "Actual rate, ticks fired and missed, lateness percentiles; start/stop buttons.",
  create(ctx, p) {
    const out = ctx.output(EMPTY_SHAPE);
    const timer = ctx.every(ctx.desiredRate, (t) => {
      const f = out.frame(1);
      f.t[0] = t;
      out.emit(f);
    });
    const describe = () => {
      ctx.setText(
        timer.running ? (timer.missed > 0 ? `missed ${timer.missed} ticks` : "") : "stopped",
      );
    };
    return {
      start() {
        if (p.Autostart) timer.start();
        describe();
      },
      stop() {
        timer.stop();
      },
      actions: {
        start: {
          label: "Start",
          description: "Start ticking",
          run() {
            timer.start();
            describe();
            return "timer started";
          },
        },
        stop: {
          label: "Stop",
          description: "Stop ticking (downstream blocks go idle)",
          run() {
            timer.stop();
            describe();
            return "timer stopped";
          },
        },
      },
    };
  },
});
