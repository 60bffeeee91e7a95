import { z } from "zod";
import { defineBlock } from "../../engine";
import { indexListArg } from "../shared/args";
import { checkIndices, inputName, signalInput } from "../shared/inputs";
import { index } from "../shared/params";
import { MAX_CHANNELS } from "../shared/limits";

const MODES = ["zero", "hold", "nan"] as const;
type Mode = (typeof MODES)[number];

export const ChannelSelector = defineBlock({
  type: "ChannelSelector",
  category: "Flow control",
  summary:
    "Activates, deactivates or zeroes channels while running; the output keeps the input's shape.",
  help:
    "Passes the active channels of its input unchanged and replaces the others (paper Table 3), " +
    "so that a bad electrode can be silenced without restarting the pipeline. A channel is a " +
    "column: an element of a vector, or the same column in every row of a matrix (a window). " +
    "`Active` lists the 0-based channels that pass (default: all); `Inactive` says what the " +
    "others output: `zero`, `hold` (the last value the channel had while it was active; 0 if it " +
    "never was) or `nan`. Both can be changed while running, and the actions `activate`, " +
    "`deactivate` and `toggle` (a channel index or a list such as [0, 3]), `all` and `none` change " +
    "the active set; `reset` returns to `Active`. The output always has the input's shape: " +
    "MOSAIC's option to delete inactive channels (a narrower output) is not offered, because " +
    "shapes are fixed when the pipeline loads — use a Projector for a fixed subset. Timestamps " +
    "are copied.",
  params: z.strictObject({
    Active: z
      .array(index())
      .max(MAX_CHANNELS)
      .optional()
      .describe(
        "0-based channels that pass (default: all; [] passes none); can be changed while running",
      ),
    Inactive: z
      .enum(MODES)
      .default("zero")
      .describe(
        "What an inactive channel outputs: zero; hold (its last value while active); nan. Can " +
          "be changed while running",
      ),
  }),
  legacyParams: () => ({}),
  legacyForm: "no params: `{ Type: ChannelSelector, Inputs: [Emg] }` (all channels active)",
  inputs: { min: 1, max: 1, labels: ["signal"] },
  live: ["Active", "Inactive"],
  views: ["scope"],
  panel: "A checkbox per channel, the inactive-channel mode, and a scope of the output.",
  create(ctx, p) {
    const sig = signalInput(ctx, 0);
    const { rows, cols } = sig.shape;
    const size = sig.size;
    const what = `input ${inputName(sig.info)}`;
    const unit = rows === 1 ? "channel" : "column";
    if (p.Active !== undefined) checkIndices(p.Active, cols, what, "Active", unit);
    const out = ctx.output(sig.shape);
    const active = new Uint8Array(cols);
    const last = new Float64Array(size);
    let mode: Mode = p.Inactive;
    let initial: readonly number[] | undefined = p.Active;

    const describe = (): void => {
      let n = 0;
      const off: number[] = [];
      for (let c = 0; c < cols; c++) {
        if (active[c]) n++;
        else off.push(c);
      }
      const shown = off.length > 12 ? `${off.slice(0, 12).join(", ")}, …` : off.join(", ");
      const verb = mode === "zero" ? "zeroed" : mode === "hold" ? "held" : "NaN";
      ctx.setText(
        off.length === 0
          ? `all ${cols} channels active`
          : `${n}/${cols} channels active (${shown} ${verb})`,
      );
    };
    const apply = (list: readonly number[] | undefined): void => {
      if (list === undefined) active.fill(1);
      else {
        active.fill(0);
        for (const c of list) active[c] = 1;
      }
      describe();
    };
    apply(initial);

    const channels = (arg: unknown): number[] =>
      indexListArg(arg, cols, `a channel of ${what} (or a list of them)`);
    const done = (): string => {
      describe();
      const on: number[] = [];
      for (let c = 0; c < cols; c++) if (active[c]) on.push(c);
      return `active channels: ${on.length === 0 ? "none" : on.join(", ")}`;
    };

    return {
      process(f) {
        const n = f.n;
        if (n === 0) return;
        const o = out.frame(n);
        const ov = o.v;
        const v = f.v;
        const ft = f.t;
        for (let e = 0; e < n; e++) {
          o.t[e] = ft[e]!;
          const base = e * size;
          for (let r = 0; r < rows; r++) {
            const off = r * cols;
            for (let c = 0; c < cols; c++) {
              const i = off + c;
              if (active[c]) {
                const x = v[base + i]!;
                ov[base + i] = x;
                last[i] = x;
              } else {
                ov[base + i] = mode === "zero" ? 0 : mode === "nan" ? NaN : last[i]!;
              }
            }
          }
        }
        out.emit(o);
      },
      reset() {
        last.fill(0);
        apply(initial);
      },
      setParam(name, value) {
        if (name === "Active") {
          const list = value as number[] | undefined;
          if (list !== undefined) checkIndices(list, cols, what, "Active", unit);
          initial = list;
          apply(list);
        } else if (name === "Inactive") {
          mode = value as Mode;
          describe();
        }
      },
      actions: {
        activate: {
          label: "Activate",
          description: "Let these channels pass (an index or a list)",
          run(arg) {
            for (const c of channels(arg)) active[c] = 1;
            return done();
          },
        },
        deactivate: {
          label: "Deactivate",
          description: "Replace these channels (an index or a list) as Inactive says",
          run(arg) {
            for (const c of channels(arg)) active[c] = 0;
            return done();
          },
        },
        toggle: {
          label: "Toggle",
          description: "Switch these channels (an index or a list) on or off",
          run(arg) {
            for (const c of new Set(channels(arg))) active[c] = active[c] ? 0 : 1;
            return done();
          },
        },
        all: {
          label: "All",
          description: "Activate every channel",
          run() {
            active.fill(1);
            return done();
          },
        },
        none: {
          label: "None",
          description: "Deactivate every channel",
          run() {
            active.fill(0);
            return done();
          },
        },
      },
    };
  },
});
