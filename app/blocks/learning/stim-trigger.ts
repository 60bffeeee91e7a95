import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  vectorShape,
  type BlockContext,
  type BlockInstance,
  type Frame,
  type InputInfo,
  type OutputPort,
} from "../../engine";
import { inputName, vectorInput } from "../shared/inputs";
import { lookup } from "../shared/named";
import { formatVector } from "../shared/text";
import type { StimulusTriggers } from "./stimulus";

export const StimTrigger = defineBlock({
  type: "StimTrigger",
  category: "Learning",
  summary:
    "The automatic Trigger of a Stimulus: its capture phases as start and stop events for a Buffer or a predictor.",
  help:
    "MOSAIC's StimTrigger turned a Stimulus's (state, target) events into the commands a Buffer " +
    "records by: the target while the Stimulus is in its capture phase, and one stop when the " +
    "capture ends. Here it sends the Buffer's trigger protocol: the task's target vector when a " +
    "capture starts and all NaN when it ends (the Stimulus's `trigger` output, which it " +
    "forwards). Wired as MOSAIC's files write it, to the Stimulus's default output " +
    "(`Inputs: [Stim]`, the cue shown to the participant, which does not say which phase a tick " +
    "is in), it reads the Stimulus's capture phases by name instead (on the same worker); wired " +
    "to `Stim.trigger` it simply forwards it. Plug it into a Buffer's trigger input (MOSAIC's " +
    "`Inputs: [StimTrigger, -Data]`), an IncrementalPredictor's target input or a TAC's target " +
    "input. Aperiodic; no params.",
  params: z.strictObject({}),
  legacyParams: () => ({}),
  legacyForm: "no params: `{ Type: StimTrigger, Inputs: [Stimulus] }`",
  inputs: { min: 1, max: 1, labels: ["stimulus"] },
  outputs: ["target"],
  views: ["label"],
  panel: "Whether a capture is in progress, and its target.",
  create(ctx) {
    const info = ctx.inputs[0];
    checkStimulus(info);
    const T = vectorInput(ctx, 0).size;
    const stimulus = namedStimulus(info);
    if (ctx.declaredRate === undefined) ctx.setDesiredRate(0);
    const out = ctx.output(vectorShape(T), "target");
    return new StimTriggerRun(ctx, out, T, stimulus).instance();
  },
});

/** The input must be a Stimulus when its type is known (MOSAIC's took a Stimulus only). */
function checkStimulus(info: InputInfo | undefined): void {
  if (info !== undefined && info.type !== undefined && info.type !== "Stimulus") {
    throw new BlockConfigError(
      `input ${inputName(info)} is a ${info.type}; StimTrigger reads a Stimulus (as MOSAIC's, ` +
        "which took a Stimulus only)",
    );
  }
}

/**
 * The Stimulus whose trigger frames are read by name, or undefined to forward the input. Wired to
 * the Stimulus's trigger output: forward it. Wired to another of its outputs (its default, the
 * cue, as MOSAIC's files write it): read its trigger frames by name; any other output is an error.
 */
function namedStimulus(info: InputInfo | undefined): string | undefined {
  if (info === undefined || info.type !== "Stimulus" || info.port === "trigger") return undefined;
  if (info.port !== "target") {
    throw new BlockConfigError(
      `input ${inputName(info)} is the Stimulus's '${info.port}' output; write Inputs: ` +
        `[${info.block}] or [${info.block}.trigger]`,
    );
  }
  return info.block;
}

/** One StimTrigger at run time: forwards the trigger frames, counts the captures, says so. */
class StimTriggerRun {
  private captures = 0;
  private capturing = false;
  private unlisten: (() => void) | undefined;

  constructor(
    private readonly ctx: BlockContext,
    private readonly out: OutputPort,
    /** Values per event (the target's width). */
    private readonly T: number,
    /** The Stimulus read by name; undefined when the input (its trigger output) is forwarded. */
    private readonly stimulus: string | undefined,
  ) {
    this.describe();
  }

  /** The block instance the engine drives. */
  instance(): BlockInstance {
    return {
      start: () => this.listen(),
      process: (f) => {
        if (this.stimulus === undefined) this.forward(f);
      },
      reset: () => {
        this.captures = 0;
        this.capturing = false;
        this.describe();
      },
      dispose: () => {
        this.unlisten?.();
        this.unlisten = undefined;
      },
    };
  }

  /** Subscribes (once) to the named Stimulus's trigger frames; warns when it cannot be read. */
  private listen(): void {
    const name = this.stimulus;
    if (name === undefined || this.unlisten) return;
    const s = lookup<StimulusTriggers>(this.ctx, name, "Stimulus");
    if (typeof s === "string") {
      this.ctx.warn(`cannot read the Stimulus's capture phases: ${s}; wire ${name}.trigger`);
      return;
    }
    this.unlisten = s.onTrigger(this.forward);
  }

  /** Sends a trigger frame on and counts the captures it starts (bound: also the listener). */
  private readonly forward = (f: Frame): void => {
    const n = f.n;
    if (n === 0) return;
    const T = this.T;
    const o = this.out.frame(n);
    o.t.set(f.t.subarray(0, n));
    o.v.set(f.v.subarray(0, n * T));
    this.out.emit(o);
    for (let e = 0; e < n; e++) {
      const stop = Number.isNaN(f.v[e * T]!);
      if (!stop && !this.capturing) this.captures++;
      this.capturing = !stop;
    }
    this.describe(this.capturing ? f.v.subarray((n - 1) * T, n * T) : undefined);
  };

  /** The status: the target being captured, else waiting or idle with the captures so far. */
  private describe(target?: ArrayLike<number>): void {
    const captures = this.captures;
    this.ctx.setText(
      target !== undefined
        ? `capturing ${formatVector(target)}`
        : captures === 0
          ? "waiting for a capture"
          : `idle (${captures} capture${captures === 1 ? "" : "s"})`,
    );
  }
}
