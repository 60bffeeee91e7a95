/**
 * A Trigger's condition input (trigger.ts): the selected label is captured while the input's
 * value at `Condition.Channel` is above `Above` (and/or below `Below`).
 */
import { BlockConfigError, type BlockContext, type Frame } from "../../engine";
import { inputName, signalInput, type SignalInput } from "../shared/inputs";

export interface Condition {
  Channel: number;
  Above?: number | undefined;
  Below?: number | undefined;
}

/** The condition with an input and no `Condition` param. */
const DEFAULT_CONDITION: Condition = { Channel: 0, Above: 0.5 };

/** Why `c` does not fit `input` (its Channel is out of range), or undefined when it does. */
function channelProblem(c: Condition, input: SignalInput): string | undefined {
  if (c.Channel < input.size) return undefined;
  return (
    `Condition.Channel ${c.Channel} is out of range for input ${inputName(input.info)} with ` +
    `${input.size} value${input.size === 1 ? "" : "s"} (valid: 0–${input.size - 1})`
  );
}

/** The condition on the Trigger's input; null without an input (then `Condition` must be left out). */
export function conditionGate(
  ctx: BlockContext,
  condition: Condition | undefined,
): ConditionGate | null {
  const input = ctx.inputs.length > 0 ? signalInput(ctx, 0) : null;
  if (input === null) {
    if (condition !== undefined) {
      throw new BlockConfigError(
        "Condition needs an input to compare (e.g. Inputs: [FootSwitch]); without one, leave it out",
        "Condition",
      );
    }
    return null;
  }
  const c = condition ?? DEFAULT_CONDITION;
  const problem = channelProblem(c, input);
  if (problem !== undefined) throw new BlockConfigError(problem, "Condition");
  return new ConditionGate(input, c);
}

export class ConditionGate {
  /** Whether the condition held at the last event. */
  private on = false;

  constructor(
    private readonly input: SignalInput,
    private condition: Condition,
  ) {}

  /** A new `Condition` while running (undefined: the default); throws when it does not fit. */
  set(value: Condition | undefined): void {
    const c = value ?? DEFAULT_CONDITION;
    const problem = channelProblem(c, this.input);
    if (problem !== undefined) throw new Error(problem);
    this.condition = c;
  }

  /** Forgets the last state: the next event that holds starts a capture. */
  reset(): void {
    this.on = false;
  }

  /** Calls `change(t, on)` at each event of `f` where the condition starts or stops holding; returns whether any did. */
  changes(f: Frame, change: (t: number, on: boolean) => void): boolean {
    const n = f.n;
    const stride = f.stride;
    const { Channel: ch, Above: above, Below: below } = this.condition;
    let changed = false;
    for (let e = 0; e < n; e++) {
      const x = f.v[e * stride + ch]!;
      const on = (above === undefined || x > above) && (below === undefined || x < below);
      if (on === this.on) continue;
      this.on = on;
      changed = true;
      change(f.t[e]!, on);
    }
    return changed;
  }
}
