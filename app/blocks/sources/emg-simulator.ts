import { z } from "zod";
import { BlockConfigError, closest, defineBlock, errorMessage, vectorShape } from "../../engine";
import { EmgSynth } from "../../engine/dsp";
import { requireDsp } from "../shared/dsp";
import { inputName, timerInput, vectorInput } from "../shared/inputs";
import { MAX_ITEMS, MAX_SEQUENCE } from "../shared/limits";

/** Names of the default gesture set, in output (one-hot) order. */
export const DEFAULT_GESTURES = [
  "rest",
  "fist",
  "open",
  "pinch",
  "flexion",
  "extension",
  "pronation",
  "supination",
] as const;

/** Resting activation of every channel. */
const REST = 0.02;

/**
 * Spatial patterns of the default gestures around the forearm: activation of channel k (at angle
 * θ_k = 2πk/C) is `base + peak · exp(κ (cos(θ_k − μ) − 1))` (a von Mises bump, 1 at μ), capped at 1.
 */
const PATTERNS: Record<
  Exclude<(typeof DEFAULT_GESTURES)[number], "rest">,
  [number, number, number, number]
> = {
  //            base  peak  μ (rad)          κ
  fist: [0.45, 0.4, 0, 1.5],
  open: [0.05, 0.7, (3 * Math.PI) / 4, 2],
  pinch: [0.05, 0.55, Math.PI / 4, 4],
  flexion: [0.05, 0.85, 0, 3],
  extension: [0.05, 0.85, Math.PI, 3],
  pronation: [0.05, 0.7, Math.PI / 2, 3],
  supination: [0.05, 0.7, (3 * Math.PI) / 2, 3],
};

/** The default gesture set for `channels` electrodes evenly spaced around the forearm. */
export function defaultGestures(channels: number): Record<string, number[]> {
  const out: Record<string, number[]> = { rest: new Array<number>(channels).fill(REST) };
  for (const [name, [base, peak, mu, kappa]] of Object.entries(PATTERNS)) {
    out[name] = Array.from({ length: channels }, (_, k) => {
      const theta = (2 * Math.PI * k) / channels;
      return Math.min(1, base + peak * Math.exp(kappa * (Math.cos(theta - mu) - 1)));
    });
  }
  return out;
}

const gestureNames = (p: { Gestures?: Record<string, number[]> | undefined }): string[] =>
  p.Gestures !== undefined ? Object.keys(p.Gestures) : [...DEFAULT_GESTURES];

const unknownGesture = (name: string, names: readonly string[]): string => {
  const s = closest(name, names);
  return (
    `unknown gesture '${name}' (gestures: ${names.join(", ")})` +
    (s !== undefined ? `; did you mean '${s}'?` : "")
  );
};

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
    requireDsp(ctx.type);
    const timer = timerInput(ctx, 0);
    if (!(timer.rate > 0)) {
      throw new BlockConfigError(
        `the rate of timer ${inputName(timer)} is unknown; EmgSimulator uses it as its sample rate`,
      );
    }
    const channels = p.Channels;
    const names = gestureNames(p);
    const table = p.Gestures ?? defaultGestures(channels);
    const patterns = names.map((n) => Float64Array.from(table[n]!));
    const indexOf = (name: string): number => {
      const i = names.indexOf(name);
      if (i < 0) throw new Error(unknownGesture(name, names));
      return i;
    };
    let synth: EmgSynth;
    try {
      synth = new EmgSynth({
        channels,
        sampleRate: timer.rate,
        seed: p.Seed,
        amplitudeMv: p.AmplitudeMv,
        noiseFloorMv: p.NoiseFloorMv,
        humMv: p.HumMv,
        humHz: p.HumHz,
        bandLowHz: p.BandLowHz,
        bandHighHz: p.BandHighHz,
        attackMs: p.AttackMs,
        releaseMs: p.ReleaseMs,
        modulation: p.Modulation,
      });
    } catch (e) {
      throw new BlockConfigError(`cannot create the EMG generator: ${errorMessage(e)}`);
    }
    const emg = ctx.output(vectorShape(channels), "emg", {
      labels: Array.from({ length: channels }, (_, k) => `EMG ${k + 1}`),
      unit: "mV",
    });
    const oneHot = ctx.output(vectorShape(names.length), "gesture", { labels: names });

    const seq = p.Sequence;
    // Cue inputs: a simulated participant following cues (every input after the timer).
    const cueMap = Int32Array.from(p.CueGestures ?? names, indexOf);
    const K = cueMap.length;
    const cueCount = ctx.inputs.length - 1;
    for (let i = 1; i <= cueCount; i++) {
      const c = vectorInput(ctx, i);
      if (c.size !== K) {
        throw new BlockConfigError(
          `cue input ${inputName(c.info)} carries ${c.size} values per event, but there are ${K} ` +
            `cue gestures (${names.length === K && p.CueGestures === undefined ? "every gesture" : "CueGestures"}: ` +
            `${Array.from(cueMap, (g) => names[g]).join(", ")}); set CueGestures to the ${c.size} ` +
            "gestures its values stand for",
          "CueGestures",
        );
      }
    }
    const following = cueCount > 0;
    if (following && seq !== undefined) {
      throw new BlockConfigError(
        "a Sequence and cue inputs both choose the gesture: give one or the other",
        "Sequence",
      );
    }
    const restIndex = names.indexOf("rest");
    const restPattern = restIndex >= 0 ? patterns[restIndex]! : new Float64Array(channels);
    const reaction = p.ReactionMs / 1000;
    /** Pending cue events, sorted by time: rows [qHead, qEnd) of qT / qV. */
    let qT = new Float64Array(following ? 16 : 0);
    let qV = new Float64Array(following ? 16 * K : 0);
    let qHead = 0;
    let qEnd = 0;
    const mix = new Float64Array(channels);
    /** The `gesture` output while following cues: the weight of every gesture. */
    const weights = new Float64Array(names.length);
    let dominant = -1;

    const enqueue = (t: number, v: Float64Array, off: number): void => {
      if (qEnd === qT.length) {
        if (qHead > 0) {
          qT.copyWithin(0, qHead, qEnd);
          qV.copyWithin(0, qHead * K, qEnd * K);
          qEnd -= qHead;
          qHead = 0;
        } else {
          const t2 = new Float64Array(qT.length * 2);
          t2.set(qT);
          const v2 = new Float64Array(qV.length * 2);
          v2.set(qV);
          qT = t2;
          qV = v2;
        }
      }
      // Keep the queue sorted by time (events of several inputs may interleave).
      let i = qEnd++;
      while (i > qHead && qT[i - 1]! > t) {
        qT[i] = qT[i - 1]!;
        qV.copyWithin(i * K, (i - 1) * K, i * K);
        i--;
      }
      qT[i] = t;
      for (let k = 0; k < K; k++) qV[i * K + k] = v[off + k]!;
    };

    /** Follows the cue in row `row` of the queue: new activation targets and gesture weights. */
    const follow = (row: number): void => {
      weights.fill(0);
      mix.set(restPattern);
      let sum = 0;
      for (let k = 0; k < K; k++) {
        let w = qV[row * K + k]!;
        if (!(w > 0)) continue; // NaN and negative weights count as 0
        if (w > 1) w = 1;
        const g = cueMap[k]!;
        weights[g] = weights[g]! + w;
        sum += w;
        const pat = patterns[g]!;
        for (let c = 0; c < channels; c++) mix[c] = mix[c]! + w * (pat[c]! - restPattern[c]!);
      }
      for (let c = 0; c < channels; c++) {
        const a = mix[c]!;
        mix[c] = a < 0 ? 0 : a > 1 ? 1 : a;
      }
      if (restIndex >= 0 && sum < 1) weights[restIndex] = weights[restIndex]! + (1 - sum);
      synth.setTargets(mix);
      current = -1;
      let best = 0;
      for (let g = 1; g < weights.length; g++) if (weights[g]! > weights[best]!) best = g;
      if (best !== dominant) {
        dominant = best;
        ctx.setText(`${names[best]} (following cues)`);
      }
    };

    const seqGesture = Int32Array.from(seq ?? [], (s) => indexOf(s.Gesture));
    const seqSeconds = Float64Array.from(seq ?? [], (s) => s.Seconds);
    const cycle = seqSeconds.reduce((a, b) => a + b, 0);
    let initialGesture = indexOf(p.Gesture);

    let manual = false;
    let current = -1;
    let step = 0;
    let stepEnd = NaN;
    let scratch = new Float64Array(0);

    const select = (g: number): void => {
      if (g === current) return;
      current = g;
      synth.setTargets(patterns[g]!);
      ctx.setText(
        seq !== undefined && !manual
          ? `${names[g]} (sequence step ${step + 1} of ${seq.length})`
          : names[g]!,
      );
    };
    const restart = (): void => {
      manual = false;
      step = 0;
      stepEnd = NaN;
      current = -1;
      qHead = 0;
      qEnd = 0;
      const g = seq !== undefined ? seqGesture[0]! : initialGesture;
      weights.fill(0);
      weights[g] = 1;
      dominant = g;
      select(g);
    };
    restart();

    /** The gesture at tick time t (advances the sequence). */
    const gestureAt = (t: number): number => {
      if (seq === undefined || manual) return current;
      if (Number.isNaN(stepEnd)) stepEnd = ctx.startTime + seqSeconds[0]!;
      if (t - stepEnd >= cycle) stepEnd += Math.floor((t - stepEnd) / cycle) * cycle;
      while (t >= stepEnd) {
        step = step + 1 === seqGesture.length ? 0 : step + 1;
        stepEnd += seqSeconds[step]!;
      }
      return seqGesture[step]!;
    };

    /** Generates events [from, to) of `out` with the current targets. */
    const generate = (out: Float64Array, from: number, to: number): void => {
      const count = to - from;
      if (count <= 0) return;
      if (from === 0) {
        synth.generate(out, count);
        return;
      }
      const m = count * channels;
      if (scratch.length < m) scratch = new Float64Array(Math.max(m, scratch.length * 2));
      synth.generate(scratch, count);
      const off = from * channels;
      for (let k = 0; k < m; k++) out[off + k] = scratch[k]!;
    };

    const setManual = (g: number): string => {
      manual = true;
      current = -1;
      qHead = 0;
      qEnd = 0;
      select(g);
      return `gesture: ${names[g]}`;
    };

    return {
      process(f, port) {
        const n = f.n;
        if (n === 0) return;
        if (port > 0) {
          if (manual) return;
          const stride = f.stride;
          for (let e = 0; e < n; e++) enqueue(f.t[e]! + reaction, f.v, e * stride);
          return;
        }
        const o = emg.frame(n);
        const h = oneHot.frame(n);
        const ov = o.v;
        const hv = h.v;
        const ft = f.t;
        const g = names.length;
        let runStart = 0;
        for (let e = 0; e < n; e++) {
          const t = ft[e]!;
          o.t[e] = t;
          h.t[e] = t;
          const off = e * g;
          if (following && !manual) {
            if (qEnd > qHead && qT[qHead]! <= t) {
              let row = qHead;
              while (qHead < qEnd && qT[qHead]! <= t) row = qHead++;
              generate(ov, runStart, e);
              runStart = e;
              follow(row);
              if (qHead === qEnd) qHead = qEnd = 0;
            }
            for (let k = 0; k < g; k++) hv[off + k] = weights[k]!;
            continue;
          }
          const want = gestureAt(t);
          if (want !== current) {
            generate(ov, runStart, e);
            runStart = e;
            select(want);
          }
          for (let k = 0; k < g; k++) hv[off + k] = 0;
          hv[off + current] = 1;
        }
        generate(ov, runStart, n);
        emg.emit(o);
        oneHot.emit(h);
      },
      reset() {
        synth.reset();
        restart();
      },
      setParam(name, value) {
        if (name === "Gesture") {
          const g = indexOf(value as string);
          initialGesture = g;
          setManual(g);
        }
      },
      dispose() {
        synth.dispose();
      },
      actions: {
        setGesture: {
          label: "Set gesture",
          description: `Hold a gesture (stops the Sequence until reset); one of ${names.join(", ")}`,
          run(arg) {
            if (typeof arg !== "string") {
              throw new Error(`setGesture needs a gesture name: one of ${names.join(", ")}`);
            }
            return setManual(indexOf(arg));
          },
        },
        next: {
          label: "Next gesture",
          description: "Go to the next gesture (the next Sequence step while a Sequence plays)",
          run() {
            if (seq !== undefined && !manual) {
              step = step + 1 === seqGesture.length ? 0 : step + 1;
              stepEnd = ctx.now() + seqSeconds[step]!;
              current = -1;
              select(seqGesture[step]!);
              return `gesture: ${names[current]}`;
            }
            return setManual(((current >= 0 ? current : dominant) + 1) % names.length);
          },
        },
      },
    };
  },
});
