import { z } from "zod";
import { BlockConfigError, defineBlock, EMPTY_SHAPE } from "../../engine";

/**
 * The fastest a timer is paced at, Hz. The lossless, batched scheduler keeps a timer → Sink on
 * time at 4 MHz on the 2-core build VM (5 ms batching interval; 200 kHz: 0.5 % of a core in the
 * blocks), but every tick is an event that each block after it handles, logs and sends: 100 kHz
 * leaves that work ~40× the room, and is 3× the fastest acquisition devices' rates (30 kHz
 * amplifiers; EMG at 1–4 kHz). Faster sources deliver packets: a vector of samples per tick
 * (MuoviSingleProbe's form).
 */
export const MAX_TIMER_HZ = 100_000;

export const ScheduledTimer = defineBlock({
  type: "ScheduledTimer",
  category: "Timing",
  summary: "Paces the pipeline: emits a tick at DesiredRate from the high-resolution scheduler.",
  help:
    "The primary timing source (paper III-D). Tick k is due at start + k / DesiredRate on one " +
    "high-resolution clock and is stamped with that deadline. It never loses a tick: when its " +
    "worker wakes, every tick due since the last one goes out as one frame of n events, the way " +
    "a device delivers a packet of samples. The worker wakes at most once per batching interval " +
    "(`BatchingMs`, default 5 ms; 0 wakes for every tick). `CatchUp: skip` is for control-rate " +
    "timers whose stale ticks are worthless: after a stall only the newest tick goes out and " +
    "the others are counted as missed (the block then reads lagging, for as long as the skipped " +
    "ticks span, at least 100 ms). Ticks carry no values. DesiredRate is at most 100 kHz. " +
    "Right-click actions start and stop it; with `Autostart: false` it waits for the start action.",
  params: z.strictObject({
    Autostart: z.boolean().default(true).describe("Start ticking when the pipeline starts"),
    CatchUp: z
      .enum(["all", "skip"])
      .default("all")
      .describe(
        "After a stall: all = every due tick goes out (lossless, for acquisition); skip = only " +
          "the newest, the others counted as missed (control-rate timers)",
      ),
  }),
  legacyParams: () => ({}),
  legacyForm: "no params: `{ Type: ScheduledTimer, DesiredRate: 200 }`",
  inputs: { min: 0, max: 0 },
  timer: true,
  views: ["label"],
  panel: "Actual rate, ticks fired and missed, lateness percentiles; start/stop buttons.",
  create(ctx, p) {
    if (ctx.desiredRate > MAX_TIMER_HZ) {
      throw new BlockConfigError(
        `DesiredRate ${ctx.desiredRate} Hz is above the fastest a timer is paced at, ` +
          `${MAX_TIMER_HZ} Hz: every tick is an event for every block after it; for faster ` +
          "signals send packets (a vector of samples per tick) at a lower rate",
        "DesiredRate",
      );
    }
    const out = ctx.output(EMPTY_SHAPE);
    const timer = ctx.every(
      ctx.desiredRate,
      (times, n) => {
        const f = out.frame(n);
        const t = f.t;
        for (let i = 0; i < n; i++) t[i] = times[i]!;
        out.emit(f);
      },
      { catchUp: p.CatchUp },
    );
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
