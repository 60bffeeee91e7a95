import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  errorMessage,
  legacyNumber,
  LegacyParamsError,
  type BlockAction,
  type BlockContext,
} from "../../engine";
import { AdaptiveFilterKernel } from "../../engine/dsp";
import { requireDsp } from "../shared/dsp";
import { signalInput, type SignalInput } from "../shared/inputs";
import { TextThrottle } from "../shared/text";

const params = z.strictObject({
  G1: z
    .number()
    .default(8)
    .describe(
      "Gain of the smoothed derivative magnitude LP(|ẋ|, B1) in eq. 4 (MOSAIC 1: derivative " +
        "contribution, 4th positional param)",
    ),
  G2: z
    .number()
    .default(-7)
    .describe(
      "Gain of the signal magnitude |x| in eq. 4 (MOSAIC 1: magnitude contribution, 3rd " +
        "positional param)",
    ),
  B1: z
    .number()
    .min(0)
    .default(0.7)
    .describe(
      "Cut-off (Hz) of the first-order low-pass that smooths the derivative: factor " +
        "2πB1ΔT/(1 + 2πB1ΔT) (MOSAIC 1: 1st positional param)",
    ),
  B2: z
    .number()
    .default(-1)
    .describe("Bias inside the exponential of eq. 4 (MOSAIC 1: offset, 2nd positional param)"),
  Derivative: z
    .enum(["paper", "mosaic"])
    .default("paper")
    .describe(
      "paper: LP(|ẋ|) as eq. 4 is printed; mosaic: |LP(ẋ)| as MOSAIC 1's code computes it " +
        "(files in MOSAIC 1's positional form are converted to mosaic)",
    ),
  UseTimestamps: z
    .boolean()
    .default(false)
    .describe(
      "Take ΔT from the event timestamps instead of 1 / desired rate (repeated or decreasing " +
        "timestamps fall back to 1 / desired rate); off by default for deterministic output",
    ),
});

type Params = z.output<typeof params>;

export const AdaptiveFilter = defineBlock({
  type: "AdaptiveFilter",
  category: "Signal processing",
  summary: "One-pole low-pass whose cut-off follows the signal's magnitude and rate of change.",
  help:
    "A single-pole IIR low-pass whose cut-off adapts at every sample to the magnitude of the " +
    "input and of its derivative (paper III-F, eqs. 2–4; Table 3), for heteroscedastic signals " +
    "such as sEMG envelopes: y[n] = α[n]·x[n] + (1 − α[n])·y[n−1], α = 2πF_cΔT/(1 + 2πF_cΔT), " +
    "F_c = exp(G2·|x[n]| + G1·LP(|ẋ[n]|, B1) + B2), with ẋ[n] = (x[n] − x[n−1])/ΔT and LP a " +
    "first-order low-pass d[n] = a·u[n] + (1 − a)·d[n−1] whose factor a = 2πB1ΔT/(1 + 2πB1ΔT) " +
    "comes from the cut-off B1 in Hz — how MOSAIC 1's AdaptiveFilter.cs converts its first " +
    "parameter (the paper only calls B1 a smoothing parameter). MOSAIC 1's code smooths the " +
    "signed derivative and rectifies after (|LP(ẋ)|); `Derivative: mosaic` does that, the default " +
    "follows eq. 4. Every channel (every element of a matrix) is filtered independently; the " +
    "state starts at zero as in MOSAIC 1 (so ẋ[0] = x[0]/ΔT), and ΔT = 1 / desired rate (the " +
    "input's rate, as MOSAIC 1) unless `UseTimestamps`. When F_c overflows, α = 1 (the output " +
    "follows the input). The defaults are MOSAIC 1's documented example " +
    "(`Params: ['0.7', '-1', '-7', '8']`), tuned for a normalised envelope; G1, G2, B1 and B2 can " +
    "be changed while running, and the panel shows the current cut-off.",
  params,
  legacyParams(args) {
    // An empty list means no params (the loader's convention): the defaults, MOSAIC 1's example.
    if (args.length === 0) return { Derivative: "mosaic" };
    if (args.length !== 4) {
      throw new LegacyParamsError(
        `expected [B1 (derivative cut-off, Hz), offset B2, magnitude gain G2, derivative gain G1], got ${args.length} arguments`,
      );
    }
    return {
      B1: legacyNumber(args[0]!, "derivative cut-off", "B1"),
      B2: legacyNumber(args[1]!, "offset", "B2"),
      G2: legacyNumber(args[2]!, "magnitude contribution", "G2"),
      G1: legacyNumber(args[3]!, "derivative contribution", "G1"),
      Derivative: "mosaic",
    };
  },
  legacyForm:
    "[B1, B2, G2, G1]: derivative cut-off (Hz), offset, magnitude and derivative contributions, e.g. ['0.7', '-1', '-7', '8']; converted with Derivative: mosaic",
  inputs: { min: 1, max: 1, labels: ["signal"] },
  live: ["G1", "G2", "B1", "B2"],
  views: ["scope", "label"],
  panel: "Scope of the filtered channels and the current cut-off frequency of each channel.",
  create(ctx, p) {
    requireDsp(ctx.type);
    const sig = signalInput(ctx, 0);
    const size = sig.size;
    const kernel = createKernel(size, sampleRate(ctx, sig), p);
    const current: Params = { ...p };
    const out = ctx.output(sig.shape);
    const timed = p.UseTimestamps;
    const text = new TextThrottle(0.5);
    let disposed = false;
    return {
      process(f) {
        const n = f.n;
        if (n === 0) return;
        const o = out.frame(n);
        const ft = f.t;
        for (let e = 0; e < n; e++) o.t[e] = ft[e]!;
        if (timed) kernel.processTimed(f.v, ft, o.v, n);
        else kernel.process(f.v, o.v, n);
        out.emit(o);
        if (text.due(ft[n - 1]!)) ctx.setText(cutoffText(kernel, size));
      },
      stop() {
        if (!disposed) ctx.setText(cutoffText(kernel, size));
      },
      reset() {
        kernel.reset();
        text.reset();
        ctx.setText("");
      },
      setParam(name, value) {
        const next: Params = { ...current, [name]: value };
        kernel.setGains(next.G1, next.G2, next.B1, next.B2);
        Object.assign(current, next);
      },
      actions: { cutoff: cutoffAction(kernel, size) },
      dispose() {
        disposed = true;
        kernel.dispose();
      },
    };
  },
});

/** ΔT's rate: the block's desired rate, which must be known (> 0). */
function sampleRate(ctx: BlockContext, sig: SignalInput): number {
  const rate = ctx.desiredRate;
  if (!(rate > 0)) {
    throw new BlockConfigError(
      `AdaptiveFilter needs a sampling rate for ΔT, but input '${sig.info.source}' has no ` +
        "desired rate; set DesiredRate on this block",
    );
  }
  return rate;
}

/** The filter of `channels` channels; a kernel that refuses the params is a config error. */
function createKernel(channels: number, rate: number, p: Params): AdaptiveFilterKernel {
  try {
    return new AdaptiveFilterKernel({
      channels,
      sampleRate: rate,
      g1: p.G1,
      g2: p.G2,
      b1: p.B1,
      b2: p.B2,
      order: p.Derivative,
    });
  } catch (e) {
    throw new BlockConfigError(`cannot create the filter: ${errorMessage(e)}`);
  }
}

/** The status: the cut-off of the first four channels. */
function cutoffText(kernel: AdaptiveFilterKernel, size: number): string {
  const parts: string[] = [];
  for (let c = 0; c < Math.min(size, 4); c++) parts.push(kernel.cutoff(c).toPrecision(3));
  return `F_c ${parts.join(", ")}${size > 4 ? ", …" : ""} Hz`;
}

/** The `cutoff` action: every channel's current cut-off, one per line. */
function cutoffAction(kernel: AdaptiveFilterKernel, size: number): BlockAction {
  return {
    label: "Cut-off frequencies",
    description: "The current cut-off frequency F_c of every channel, in Hz",
    run() {
      const parts: string[] = [];
      for (let c = 0; c < size; c++) parts.push(`${c}: ${kernel.cutoff(c)} Hz`);
      return parts.join("\n");
    },
  };
}
