import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  errorMessage,
  formatShape,
  vectorShape,
  type BlockContext,
  type Frame,
  type OutputPort,
  type Shape,
} from "../../engine";
import { ARTIFACT_REASONS, ArtifactKernel } from "../../engine/dsp";
import { requireDsp } from "../shared/dsp";
import { inputName, signalInput, type SignalInput } from "../shared/inputs";
import { extendedNumber } from "../shared/params";
import { TextThrottle } from "../shared/text";

const params = z
  .strictObject({
    RailLow: z
      .number()
      .optional()
      .describe(
        "Lower rail of the signal (e.g. the ADC minimum: −1.5 mV for a PLUX 12-bit EMG sensor); " +
          "default: auto, the running minimum of the channel",
      ),
    RailHigh: z
      .number()
      .optional()
      .describe(
        "Upper rail (e.g. (4095/4096 − 0.5)·3 = 1.49927 mV for a PLUX 12-bit EMG sensor); " +
          "default: auto, the running maximum of the channel",
      ),
    ClipTolerance: z
      .number()
      .min(0)
      .default(1e-6)
      .describe("A sample within this distance of a rail (signal units) is on it"),
    ClipFraction: z
      .number()
      .min(0)
      .max(1)
      .default(0)
      .describe(
        "Fraction of a window's samples that must be on one rail to call it clipped (at least 1 " +
          "sample for a fixed rail, 2 for an auto rail); 0: any",
      ),
    FlatThreshold: z
      .number()
      .min(0)
      .default(1e-6)
      .describe("Flat line: the window's standard deviation is below this (signal units)"),
    JumpFactor: extendedNumber()
      .default(50)
      .describe(
        "Impulsive jump: the largest step deviates from the median step by more than JumpFactor " +
          "× 1.4826·MAD of the steps (a robust z-score); .inf disables the test",
      ),
    DriftThreshold: z
      .number()
      .min(0)
      .optional()
      .describe("Drift: |window mean| above this (signal units); default: off"),
    Mode: z
      .enum(["hard", "soft"])
      .default("hard")
      .describe("hard: rejected channels are zeroed in `clean`; soft: `clean` passes unchanged"),
  })
  .refine((p) => !(p.JumpFactor <= 0), {
    message: "JumpFactor must be positive",
    path: ["JumpFactor"],
  })
  .refine((p) => p.RailLow === undefined || p.RailHigh === undefined || p.RailLow < p.RailHigh, {
    message: "RailLow must be below RailHigh",
    path: ["RailLow"],
  });

const SHORT = ["clip", "flat", "jump", "drift", "nonfinite"] as const;

type Params = z.output<typeof params>;

/** The input, windows [L, C] with L ≥ 3. */
function windowInput(ctx: BlockContext): SignalInput {
  const sig = signalInput(ctx, 0);
  if (sig.shape.rows < 3) {
    throw new BlockConfigError(
      `input ${inputName(sig.info)} has shape ${formatShape(sig.shape)}; ArtifactRejection ` +
        "judges windows [L, C] with L ≥ 3: put a SlidingWindow before it",
    );
  }
  return sig;
}

function createKernel(p: Params, rows: number, cols: number): ArtifactKernel {
  try {
    return new ArtifactKernel({
      rows,
      channels: cols,
      ...(p.RailLow !== undefined ? { railLow: p.RailLow } : {}),
      ...(p.RailHigh !== undefined ? { railHigh: p.RailHigh } : {}),
      clipTolerance: p.ClipTolerance,
      clipFraction: p.ClipFraction,
      flatThreshold: p.FlatThreshold,
      jumpFactor: p.JumpFactor,
      ...(p.DriftThreshold !== undefined ? { driftThreshold: p.DriftThreshold } : {}),
      hard: p.Mode === "hard",
    });
  } catch (e) {
    throw new BlockConfigError(`cannot create the artifact rules: ${errorMessage(e)}`);
  }
}

/** The status line: rejected channel-windows per reason, and the first 4 channels rejected. */
function summaryText(kernel: ArtifactKernel, cols: number): string {
  const total = [0, 0, 0, 0, 0, 0];
  const bad: string[] = [];
  for (let c = 0; c < cols; c++) {
    for (let r = 0; r < 6; r++) total[r]! += kernel.counter(c, r);
    if (kernel.counter(c, 5) > 0 && bad.length < 4) {
      const why = SHORT.map((s, r) => [s, kernel.counter(c, r)] as const)
        .filter(([, v]) => v > 0)
        .map(([s, v]) => `${s} ${v}`)
        .join(" ");
      bad.push(`ch${c}: ${why}`);
    }
  }
  const reasons = SHORT.map((s, r) => `${s} ${total[r]}`).join(", ");
  const cells = kernel.windows() * cols;
  return (
    `rejected ${total[5]} of ${cells} channel-windows (${reasons})` +
    (bad.length > 0 ? `; ${bad.join("; ")}${total[5]! > 0 && bad.length === 4 ? "; …" : ""}` : "")
  );
}

/** The `counters` action's answer: one CSV line per channel. */
function countersText(kernel: ArtifactKernel, cols: number): string {
  const lines = [`windows ${kernel.windows()}`, `channel,${ARTIFACT_REASONS.join(",")},rejected`];
  for (let c = 0; c < cols; c++) {
    const row = [0, 1, 2, 3, 4, 5].map((r) => kernel.counter(c, r));
    lines.push(`${c},${row.join(",")}`);
  }
  return lines.join("\n");
}

/** One ArtifactRejection at run time: the kernel, its outputs and the status line. */
class ArtifactRun {
  private readonly clean: OutputPort;
  private readonly mask: OutputPort;
  private readonly cols: number;
  private readonly text = new TextThrottle(0.5);
  private disposed = false;

  constructor(
    private readonly ctx: BlockContext,
    private readonly kernel: ArtifactKernel,
    shape: Shape,
  ) {
    this.cols = shape.cols;
    this.clean = ctx.output(shape, "clean");
    this.mask = ctx.output(vectorShape(shape.cols), "mask");
    this.showSummary();
  }

  process(f: Frame): void {
    const n = f.n;
    if (n === 0) return;
    const co = this.clean.frame(n);
    const mo = this.mask.frame(n);
    this.kernel.process(f.v, n, co.v, mo.v);
    const ft = f.t;
    for (let e = 0; e < n; e++) {
      co.t[e] = ft[e]!;
      mo.t[e] = ft[e]!;
    }
    this.clean.emit(co);
    this.mask.emit(mo);
    // The status line is rebuilt at most every 0.5 s of pipeline time, and when it stops.
    if (this.text.due(ft[n - 1]!)) this.showSummary();
  }

  stop(): void {
    if (!this.disposed) this.showSummary();
  }

  reset(): void {
    this.kernel.reset();
    this.text.reset();
    this.showSummary();
  }

  resetCounters(): string {
    this.kernel.resetCounters();
    this.showSummary();
    return "counters reset";
  }

  counters(): string {
    return countersText(this.kernel, this.cols);
  }

  dispose(): void {
    this.disposed = true;
    this.kernel.dispose();
  }

  private showSummary(): void {
    this.ctx.setText(summaryText(this.kernel, this.cols));
  }
}

export const ArtifactRejection = defineBlock({
  type: "ArtifactRejection",
  category: "Flow control",
  summary: "Rule-based rejection of clipped, flat, jumping or drifting channels of every window.",
  help:
    "Judges every channel of every window [L, C] (from SlidingWindow; L ≥ 3) with simple rules " +
    "(paper Table 3) and outputs `clean` (the window; rejected channels zeroed in `Mode: hard`, " +
    "unchanged in `soft`) and `mask` [1, C] (1 = good, 0 = rejected), both with the window's " +
    "timestamp. Rules: **clipping**, a fraction ≥ `ClipFraction` of the samples (at least one) " +
    "within `ClipTolerance` of `RailLow` or `RailHigh` — give the ADC range when you know it; " +
    "otherwise a rail is the running minimum/maximum of the channel, and since the window that " +
    "sets an extreme always has one sample on it, an auto rail needs two samples on it and is " +
    "judged from the second window on; **flat line**, standard deviation < `FlatThreshold`; " +
    "**impulsive jump**, max_i |Δ_i − med(Δ)| > `JumpFactor` · 1.4826 · MAD(Δ) over the steps " +
    "Δ_i = x_{i+1} − x_i (a robust z-score, Iglewicz & Hoaglin 1993; 1.253314 × the mean " +
    "absolute deviation when the MAD is 0); **drift**, |mean| > `DriftThreshold` (off by " +
    "default); and any NaN or infinite sample. Counters per reason and per channel accumulate " +
    "for reproducibility: the status line shows them, the `counters` action lists them per " +
    "channel and `resetCounters` zeroes them (`reset` also forgets the auto rails). The defaults " +
    "reject no window of the clean `emg_bursts_1000hz.csv` recording (200-sample windows every " +
    "50) and, with the sensor's rails, find all 38 rail samples of `emg_fatigue_1000hz.csv`.",
  params,
  inputs: { min: 1, max: 1, labels: ["windows"] },
  outputs: ["clean", "mask"],
  views: ["heatmap", "label"],
  panel:
    "Mask of the latest window per channel and the cumulative counters per reason and channel.",
  create(ctx, p) {
    requireDsp(ctx.type);
    const sig = windowInput(ctx);
    const run = new ArtifactRun(ctx, createKernel(p, sig.shape.rows, sig.shape.cols), sig.shape);
    return {
      process(f) {
        run.process(f);
      },
      stop() {
        run.stop();
      },
      reset() {
        run.reset();
      },
      actions: {
        resetCounters: {
          label: "Reset counters",
          description:
            "Zeroes the counters per reason and channel (the learned auto rails are kept)",
          run: () => run.resetCounters(),
        },
        counters: {
          label: "Counters per channel",
          description: "Windows rejected per channel and per reason since the last reset",
          run: () => run.counters(),
        },
      },
      dispose() {
        run.dispose();
      },
    };
  },
});
