import { z } from "zod";
import { BlockConfigError, defineBlock, vectorShape } from "../../engine";
import { inputName, vectorInput } from "../shared/inputs";
import { formatVector } from "../shared/text";

export const StimTrigger = defineBlock({
  type: "StimTrigger",
  category: "Learning",
  summary:
    "The automatic Trigger of a Stimulus: its capture phases as start and stop events for a Buffer or a predictor.",
  help:
    "MOSAIC's StimTrigger turned a Stimulus's (state, target) events into the commands a Buffer " +
    "records by: the target while the Stimulus is in its capture phase, and one stop when the " +
    "capture ends. Here the Stimulus offers exactly that on its `trigger` output (the Buffer's " +
    "trigger protocol: the task's target vector when a capture starts, all NaN when it ends), and " +
    "StimTrigger forwards it, checked: its input must be a Stimulus's `trigger` output, written " +
    "`Inputs: [Stim.trigger]`. The Stimulus's default output (`target`, the cue shown to the " +
    "participant) does not say which phase a tick belongs to, so `Inputs: [Stim]` is refused with " +
    "that fix, unless the loader resolves it to the trigger port. Plug the output into a Buffer's " +
    "trigger input (MOSAIC's `Inputs: [StimTrigger, -Data]`), an IncrementalPredictor's target " +
    "input or a TAC's target input. Aperiodic; no params.",
  params: z.strictObject({}),
  legacyParams: () => ({}),
  legacyForm: "no params: `{ Type: StimTrigger, Inputs: [Stimulus.trigger] }`",
  inputs: { min: 1, max: 1, labels: ["stimulus"] },
  outputs: ["target"],
  views: ["label"],
  panel: "Whether a capture is in progress, and its target.",
  create(ctx) {
    const info = ctx.inputs[0];
    if (info !== undefined && info.type === "Stimulus" && info.port !== "trigger") {
      throw new BlockConfigError(
        `input ${inputName(info)} is the Stimulus's '${info.port}' output, which does not say when ` +
          `a capture starts and ends: write Inputs: [${info.block}.trigger] (its capture phases ` +
          "as start and stop events)",
      );
    }
    if (info !== undefined && info.type !== undefined && info.type !== "Stimulus") {
      throw new BlockConfigError(
        `input ${inputName(info)} is a ${info.type}; StimTrigger reads a Stimulus's trigger ` +
          "output (as MOSAIC's, which took a Stimulus only)",
      );
    }
    const input = vectorInput(ctx, 0);
    const T = input.size;
    if (ctx.declaredRate === undefined) ctx.setDesiredRate(0);
    const out = ctx.output(vectorShape(T), "target");
    let captures = 0;
    let capturing = false;
    const describe = (target?: ArrayLike<number>): void =>
      ctx.setText(
        target !== undefined
          ? `capturing ${formatVector(target)}`
          : captures === 0
            ? "waiting for a capture"
            : `idle (${captures} capture${captures === 1 ? "" : "s"})`,
      );
    describe();
    return {
      process(f) {
        const n = f.n;
        if (n === 0) return;
        const o = out.frame(n);
        o.t.set(f.t.subarray(0, n));
        o.v.set(f.v.subarray(0, n * T));
        out.emit(o);
        for (let e = 0; e < n; e++) {
          const stop = Number.isNaN(f.v[e * T]!);
          if (!stop && !capturing) captures++;
          capturing = !stop;
        }
        describe(capturing ? f.v.subarray((n - 1) * T, n * T) : undefined);
      },
      reset() {
        captures = 0;
        capturing = false;
        describe();
      },
    };
  },
});
