/**
 * EmgSimulator: seeded surface EMG. The block's definition; the simulator is in emg-simulator-*.ts:
 * -gestures (the default set and a block's gestures), -run (the simulator: generating frames,
 * holding a gesture, the status text), -sequence (a Sequence played by tick time), -cues (the
 * simulated participant following cue inputs) and -instance (its actions).
 */
import { z } from "zod";
import { defineBlock } from "../../engine";
import { MAX_ITEMS, MAX_SEQUENCE } from "../shared/limits";
import { gestureNames, unknownGesture } from "./emg-simulator-gestures";
import { simulatorInstance } from "./emg-simulator-instance";
import { SimulatorRun } from "./emg-simulator-run";

export { DEFAULT_GESTURES, defaultGestures } from "./emg-simulator-gestures";

const params = z
  .strictObject({
    Channels: z
      .number()
      .int()
      .min(1)
      .max(4096)
      .default(8)
      .describe("Number of electrodes, evenly spaced around the forearm (8 like a Myo armband)"),
    Seed: z
      .number()
      .int()
      .min(0)
      .max(Number.MAX_SAFE_INTEGER)
      .default(42)
      .describe("Seed of the random streams: the same seed gives the same signal"),
    Gesture: z
      .string()
      .min(1)
      .default("rest")
      .describe("Gesture held from the start (ignored while a Sequence plays)"),
    Gestures: z
      .record(z.string().min(1), z.array(z.number().min(0).max(1)).min(1).max(4096))
      .refine((g) => Object.keys(g).length <= MAX_ITEMS, {
        message: `at most ${MAX_ITEMS} gestures`,
      })
      .optional()
      .describe(
        "Gestures by name, each a per-channel activation vector of Channels values from 0 " +
          "(rest) to 1 (full contraction); default: rest, fist, open, pinch, flexion, extension, " +
          "pronation, supination as smooth patterns around the forearm",
      ),
    Sequence: z
      .array(
        z.strictObject({
          Gesture: z.string().min(1).describe("Gesture name"),
          Seconds: z.number().positive().describe("How long it is held, in seconds"),
        }),
      )
      .min(1)
      .max(MAX_SEQUENCE)
      .optional()
      .describe(
        "Gestures played one after the other from the pipeline start and cycled, e.g. " +
          "[{Gesture: rest, Seconds: 2}, {Gesture: fist, Seconds: 2}]",
      ),
    CueGestures: z
      .array(z.string().min(1))
      .min(1)
      .max(MAX_ITEMS)
      .optional()
      .describe(
        "With cue inputs: the gesture that each value of a cue event stands for, e.g. [fist, " +
          "open] for a Stimulus with targets [1, 0] and [0, 1] (default: every gesture, in the " +
          "order of Gestures)",
      ),
    ReactionMs: z
      .number()
      .min(0)
      .max(10_000)
      .default(0)
      .describe(
        "With cue inputs: the simulated participant's reaction time, in ms (a cue is followed " +
          "this long after its timestamp)",
      ),
    AmplitudeMv: z
      .number()
      .min(0)
      .default(0.5)
      .describe("RMS of the EMG at full activation, in mV"),
    NoiseFloorMv: z
      .number()
      .min(0)
      .default(0.01)
      .describe("RMS of the white electrode/amplifier noise, in mV"),
    HumMv: z.number().min(0).default(0.02).describe("Amplitude of the powerline hum, in mV"),
    HumHz: z
      .union([z.literal(50), z.literal(60)])
      .default(50)
      .describe("Powerline frequency: 50 Hz (Europe, Asia) or 60 Hz (the Americas)"),
    BandLowHz: z
      .number()
      .min(0)
      .default(20)
      .describe("High-pass corner of the EMG band, in Hz (0 for none)"),
    BandHighHz: z
      .number()
      .positive()
      .default(450)
      .describe("Low-pass corner of the EMG band, in Hz (limited to 0.45 × the sample rate)"),
    AttackMs: z
      .number()
      .min(0)
      .default(60)
      .describe("Time constant of the envelope when a muscle activates, in ms"),
    ReleaseMs: z
      .number()
      .min(0)
      .default(150)
      .describe("Time constant of the envelope when a muscle relaxes, in ms"),
    Modulation: z
      .number()
      .min(0)
      .max(1)
      .default(0.1)
      .describe("Depth of the slow (1–3 Hz) fluctuation of the EMG amplitude, 0 to 1"),
  })
  .superRefine((p, ctx) => {
    if (p.Gestures !== undefined) {
      for (const [name, v] of Object.entries(p.Gestures)) {
        if (v.length !== p.Channels) {
          ctx.addIssue({
            code: "custom",
            path: ["Gestures", name],
            message: `gesture '${name}' has ${v.length} activations; expected ${p.Channels} (one per channel)`,
          });
        }
      }
    }
    const names = gestureNames(p);
    if (!names.includes(p.Gesture)) {
      ctx.addIssue({
        code: "custom",
        path: ["Gesture"],
        message: unknownGesture(p.Gesture, names),
      });
    }
    p.Sequence?.forEach((s, i) => {
      if (!names.includes(s.Gesture)) {
        ctx.addIssue({
          code: "custom",
          path: ["Sequence", i, "Gesture"],
          message: unknownGesture(s.Gesture, names),
        });
      }
    });
    p.CueGestures?.forEach((g, i) => {
      if (!names.includes(g)) {
        ctx.addIssue({
          code: "custom",
          path: ["CueGestures", i],
          message: unknownGesture(g, names),
        });
      }
    });
    if (p.BandLowHz >= p.BandHighHz) {
      ctx.addIssue({
        code: "custom",
        path: ["BandLowHz"],
        message: `BandLowHz ${p.BandLowHz} must be below BandHighHz ${p.BandHighHz}`,
      });
    }
  });

export const EmgSimulator = defineBlock({
  type: "EmgSimulator",
  category: "Sources",
  summary: "Realistic seeded multi-channel surface EMG for demos, teaching and tests.",
  help:
    "Generates surface EMG the way an armband records it, one sample per tick of its timer (the " +
    "timer's rate is the sample rate). Every channel is band-limited Gaussian noise (2nd-order " +
    "Butterworth band-pass BandLowHz–BandHighHz, the usual model of the interference pattern of " +
    "many motor units) scaled to AmplitudeMv RMS at full activation, times an envelope that " +
    "follows the current gesture's activation of that channel with AttackMs/ReleaseMs time " +
    "constants and a slow 1–3 Hz fluctuation, plus white noise (NoiseFloorMv RMS) and powerline " +
    "hum (HumMv at HumHz). A gesture is a vector of per-channel activations 0..1; the default " +
    "set (rest, fist, open, pinch, flexion, extension, pronation, supination) gives each gesture " +
    "a smooth pattern around the forearm (a von Mises bump centred at its own angle, channel k " +
    "at angle 2πk/Channels), so neighbouring channels correlate as with a Myo armband. " +
    "`Sequence` cycles through gestures by tick time, which the demo and the bench use; the " +
    "`setGesture` and `next` actions (or changing Gesture while running) switch gestures by " +
    "hand, and setting a gesture stops the Sequence until `reset`. The `gesture` output is the " +
    "one-hot code of the current gesture (in the order of Gestures), for training targets. The " +
    "same Seed gives the same signal, also under a Sequence. A simulated participant follows " +
    "cues: every input after the timer is a cue input (e.g. a Stimulus's `target` output, a " +
    "Trigger's `target`), whose events are vectors of weights w_k for the gestures `CueGestures` " +
    "(default: all, in order). From the first tick at or after an event's time + ReactionMs, " +
    "the activation of every channel is rest + Σ w_k·(gesture_k − rest), clipped to 0..1 (rest: " +
    "the `rest` gesture's pattern, zeros without one; w_k clipped to 0..1, NaN counts as 0, so " +
    "an all-NaN stop means rest), so a Stimulus's sin² ramps become graded contractions; the " +
    "latest cue of any input wins, and `gesture` then carries the mixture (w_k at each cued " +
    "gesture, 1 − Σ w at rest). Cue inputs and a Sequence exclude each other; setting a gesture " +
    "by hand stops following cues until `reset`.",
  params,
  inputs: { min: 1, max: Infinity, labels: ["timer", "cue"] },
  outputs: ["emg", "gesture"],
  live: ["Gesture"],
  views: ["scope", "spider", "heatmap", "label"],
  panel: "Scope and spider plot of the channels, the current gesture and gesture buttons.",
  create(ctx, p) {
    return simulatorInstance(new SimulatorRun(ctx, p));
  },
});
