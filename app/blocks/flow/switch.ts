import { z } from "zod";
import {
  BlockConfigError,
  closest,
  defineBlock,
  formatShape,
  sameShape,
  type BlockContext,
  type BlockInstance,
  type Frame,
  type InputInfo,
  type OutputPort,
} from "../../engine";
import { indexArg } from "../shared/args";
import { inputName, signalInput, type SignalInput } from "../shared/inputs";

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
    const first = checkShapes(ctx);
    const initial = checkActive(ctx.inputs, p.Active);
    const out = ctx.output(first.shape);
    return new SwitchRun(ctx, initial, out).instance();
  },
});

/** All inputs must have the shape of the first, which is returned. */
function checkShapes(ctx: BlockContext): SignalInput {
  const n = ctx.inputs.length;
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
  return first;
}

/** `Active` at creation must be the position of an input. */
function checkActive(inputs: readonly InputInfo[], i: number): number {
  const n = inputs.length;
  if (i >= n) {
    throw new BlockConfigError(
      `Active ${i} is out of range: the Switch has ${n} inputs (${inputs.map(inputName).join(", ")}; valid: 0–${n - 1})`,
      "Active",
    );
  }
  return i;
}

/** The position of the input named `arg` (its source or its block), or an error naming them. */
function inputNamed(inputs: readonly InputInfo[], blockName: string, arg: string): number {
  const i = inputs.findIndex((x) => x.source === arg || x.block === arg);
  if (i < 0) {
    const s = closest(
      arg,
      inputs.map((x) => x.source),
    );
    throw new Error(
      `'${arg}' is not an input of ${blockName} (${inputs.map((x) => x.source).join(", ")})` +
        (s !== undefined ? `; did you mean '${s}'?` : ""),
    );
  }
  return i;
}

/** One Switch at run time: the active input, its subscriptions, rate and status. */
class SwitchRun {
  private readonly inputs: readonly InputInfo[];
  private readonly n: number;
  /** Inputs written `-Name` are subscribed only while active, as MOSAIC's Switch did. */
  private readonly onDemand: boolean[];
  private active: number;

  constructor(
    private readonly ctx: BlockContext,
    /** Where `reset` returns: Active. */
    private initial: number,
    private readonly out: OutputPort,
  ) {
    this.inputs = ctx.inputs;
    this.n = this.inputs.length;
    this.active = initial;
    this.onDemand = this.inputs.map((i) => !i.subscribed);
    this.select(this.active);
  }

  /** The block instance the engine drives, with its toggle and select actions. */
  instance(): BlockInstance {
    return {
      process: (f, port) => this.process(f, port),
      reset: () => {
        this.select(this.initial);
      },
      setParam: (name, value) => this.setParam(name, value),
      actions: {
        toggle: {
          label: "Toggle",
          description: "Forward the next input (after the last, the first)",
          run: () => this.select((this.active + 1) % this.n),
        },
        select: {
          label: "Select",
          description: "Forward this input: its position in Inputs or its name",
          run: (arg) => this.selectArg(arg),
        },
      },
    };
  }

  /** Forwards the events of the active input; the others are ignored. */
  private process(f: Frame, port: number): void {
    if (port !== this.active) return;
    const nEv = f.n;
    if (nEv === 0) return;
    const o = this.out.frame(nEv);
    o.copyEvents(f, 0, nEv, 0);
    this.out.emit(o);
  }

  /** A live Active: becomes the input forwarded, and where `reset` returns. */
  private setParam(name: string, value: unknown): void {
    if (name !== "Active") return;
    const i = value as number;
    if (i >= this.n) throw new Error(`Active ${i} is out of range (valid: 0–${this.n - 1})`);
    this.initial = i;
    this.select(i);
  }

  /** The select action: an input by name, or by position (a number or a numeric string). */
  private selectArg(arg: unknown): string {
    if (typeof arg === "string" && !/^\s*\d+\s*$/.test(arg)) {
      return this.select(inputNamed(this.inputs, this.ctx.name, arg));
    }
    return this.select(indexArg(arg, this.n, "an input position or name"));
  }

  /** Makes input i the active one: subscriptions, desired rate, status; says what it forwards. */
  private select(i: number): string {
    this.active = i;
    this.onDemand.forEach((lazy, j) => {
      if (lazy) this.ctx.setSubscribed(j, j === i);
    });
    const info: InputInfo = this.inputs[i]!;
    if (this.ctx.declaredRate === undefined) this.ctx.setDesiredRate(info.rate);
    this.describe();
    return `${this.ctx.name} forwards ${info.source}`;
  }

  /** The status: which input is forwarded. */
  private describe(): void {
    this.ctx.setText(`forwarding ${this.inputs[this.active]!.source}`);
  }
}
