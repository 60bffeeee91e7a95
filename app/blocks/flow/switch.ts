import { z } from "zod";
import {
  BlockConfigError,
  closest,
  defineBlock,
  formatShape,
  sameShape,
  type InputInfo,
} from "../../engine";
import { indexArg } from "../shared/args";
import { inputName, signalInput } from "../shared/inputs";

export const Switch = defineBlock({
  type: "Switch",
  category: "Flow control",
  summary:
    "Forwards only its active input (of two or more of the same shape); toggled at run time.",
  help:
    "Toggles between inputs of the same shape and forwards only the active one (paper Table 3), " +
    "e.g. a test signal and a trained predictor. `Active` is the 0-based position of the active " +
    "input in `Inputs` (default 0, can be changed while running); the `toggle` action moves to " +
    "the next input (after the last, back to the first) and `select` picks one by position or by " +
    "name (as written in Inputs); `reset` returns to `Active`. Events of the other inputs are " +
    "ignored. The desired rate follows the active input (unless `DesiredRate` is written). " +
    "As MOSAIC's Switch did, an input written `-Name` is subscribed only while it is active " +
    "(nothing is delivered from it otherwise); inputs written without `-` stay subscribed.",
  params: z.strictObject({
    Active: z
      .number()
      .int()
      .min(0)
      .default(0)
      .describe(
        "0-based position (in Inputs) of the input that is forwarded; can be changed while running",
      ),
  }),
  legacyParams: () => ({}),
  legacyForm: "no params: `{ Type: Switch, Inputs: [First, -Second] }` (the first is active)",
  inputs: { min: 2, max: Infinity },
  live: ["Active"],
  views: ["scope"],
  panel: "Which input is forwarded, a button per input, and a scope of the output.",
  create(ctx, p) {
    const inputs = ctx.inputs;
    const n = inputs.length;
    const first = signalInput(ctx, 0);
    for (let i = 1; i < n; i++) {
      const s = signalInput(ctx, i);
      if (!sameShape(s.shape, first.shape)) {
        throw new BlockConfigError(
          `input ${inputName(s.info)} has shape ${formatShape(s.shape)}, but ` +
            `${inputName(first.info)} has ${formatShape(first.shape)}; a Switch forwards inputs ` +
            "of one shape",
        );
      }
    }
    const check = (i: number): number => {
      if (i >= n) {
        throw new BlockConfigError(
          `Active ${i} is out of range: the Switch has ${n} inputs (${inputs.map(inputName).join(", ")}; valid: 0–${n - 1})`,
          "Active",
        );
      }
      return i;
    };
    let initial = check(p.Active);
    let active = initial;
    const out = ctx.output(first.shape);
    // Inputs written `-Name` are subscribed only while active, as MOSAIC's Switch did.
    const onDemand = inputs.map((i) => !i.subscribed);
    const describe = (): void => {
      ctx.setText(`forwarding ${inputs[active]!.source}`);
    };
    const select = (i: number): string => {
      active = i;
      onDemand.forEach((lazy, j) => {
        if (lazy) ctx.setSubscribed(j, j === i);
      });
      const info: InputInfo = inputs[i]!;
      if (ctx.declaredRate === undefined) ctx.setDesiredRate(info.rate);
      describe();
      return `${ctx.name} forwards ${info.source}`;
    };
    select(active);
    return {
      process(f, port) {
        if (port !== active) return;
        const nEv = f.n;
        if (nEv === 0) return;
        const o = out.frame(nEv);
        o.copyEvents(f, 0, nEv, 0);
        out.emit(o);
      },
      reset() {
        select(initial);
      },
      setParam(name, value) {
        if (name !== "Active") return;
        const i = value as number;
        if (i >= n) throw new Error(`Active ${i} is out of range (valid: 0–${n - 1})`);
        initial = i;
        select(i);
      },
      actions: {
        toggle: {
          label: "Toggle",
          description: "Forward the next input (after the last, the first)",
          run: () => select((active + 1) % n),
        },
        select: {
          label: "Select",
          description: "Forward this input: its position in Inputs or its name",
          run(arg) {
            if (typeof arg === "string" && !/^\s*\d+\s*$/.test(arg)) {
              const i = inputs.findIndex((x) => x.source === arg || x.block === arg);
              if (i < 0) {
                const s = closest(
                  arg,
                  inputs.map((x) => x.source),
                );
                throw new Error(
                  `'${arg}' is not an input of ${ctx.name} (${inputs.map((x) => x.source).join(", ")})` +
                    (s !== undefined ? `; did you mean '${s}'?` : ""),
                );
              }
              return select(i);
            }
            return select(indexArg(arg, n, "an input position or name"));
          },
        },
      },
    };
  },
});
