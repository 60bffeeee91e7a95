import { z } from "zod";
import { BlockConfigError, defineBlock, vectorShape, type Frame } from "../../engine";
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
    if (info !== undefined && info.type !== undefined && info.type !== "Stimulus") {
      throw new BlockConfigError(
        `input ${inputName(info)} is a ${info.type}; StimTrigger reads a Stimulus (as MOSAIC's, ` +
          "which took a Stimulus only)",
      );
    }
    // Wired to the Stimulus's trigger output: forward it. Wired to another of its outputs (its
    // default, the cue, as MOSAIC's files write it): read its trigger frames by name.
    const byName = info !== undefined && info.type === "Stimulus" && info.port !== "trigger";
    const input = vectorInput(ctx, 0);
    const T = input.size;
    if (byName && info.port !== "target") {
      throw new BlockConfigError(
        `input ${inputName(info)} is the Stimulus's '${info.port}' output; write Inputs: ` +
          `[${info.block}] or [${info.block}.trigger]`,
      );
    }
    if (ctx.declaredRate === undefined) ctx.setDesiredRate(0);
    const out = ctx.output(vectorShape(T), "target");
    let captures = 0;
    let capturing = false;
    let unlisten: (() => void) | undefined;
    const describe = (target?: ArrayLike<number>): void =>
      ctx.setText(
        target !== undefined
          ? `capturing ${formatVector(target)}`
          : captures === 0
            ? "waiting for a capture"
            : `idle (${captures} capture${captures === 1 ? "" : "s"})`,
      );
    describe();
    const forward = (f: Frame): void => {
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
    };
    return {
      start() {
        if (!byName || unlisten) return;
        const s = lookup<StimulusTriggers>(ctx, info.block, "Stimulus");
        if (typeof s === "string") {
          ctx.warn(`cannot read the Stimulus's capture phases: ${s}; wire ${info.block}.trigger`);
          return;
        }
        unlisten = s.onTrigger(forward);
      },
      process(f) {
        if (!byName) forward(f);
      },
      reset() {
        captures = 0;
        capturing = false;
        describe();
      },
      dispose() {
        unlisten?.();
        unlisten = undefined;
      },
    };
  },
});
