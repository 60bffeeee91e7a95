/**
 * One ChannelSelector at run time (channel-selector.ts): the active set of channels, what the
 * inactive ones output, the values held for `hold`, the status text and the actions.
 */
import type { BlockAction, BlockContext, BlockInstance, Frame, OutputPort } from "../../engine";
import { indexListArg } from "../shared/args";
import { checkIndices, inputName, type SignalInput } from "../shared/inputs";
import type { Mode } from "./channel-selector";

export class ChannelSelectorRun {
  private readonly out: OutputPort;
  private readonly rows: number;
  private readonly cols: number;
  private readonly size: number;
  /** "input <name>", for error messages. */
  private readonly what: string;
  /** What a column is called in error messages: channel (a vector) or column (a matrix). */
  private readonly unit: "channel" | "column";
  /** 1 for an active channel. */
  private readonly active: Uint8Array;
  /** The last value of each element while its channel was active (for `hold`). */
  private readonly last: Float64Array;
  private mode: Mode;
  /** The `Active` param: the set that reset returns to (undefined: all). */
  private initial: readonly number[] | undefined;

  constructor(
    private readonly ctx: BlockContext,
    sig: SignalInput,
    active: readonly number[] | undefined,
    inactive: Mode,
  ) {
    this.rows = sig.shape.rows;
    this.cols = sig.shape.cols;
    this.size = sig.size;
    this.what = `input ${inputName(sig.info)}`;
    this.unit = this.rows === 1 ? "channel" : "column";
    if (active !== undefined) this.checkActive(active);
    this.out = ctx.output(sig.shape);
    this.active = new Uint8Array(this.cols);
    this.last = new Float64Array(this.size);
    this.mode = inactive;
    this.initial = active;
    this.apply(this.initial);
  }

  instance(): BlockInstance {
    return {
      process: (f) => {
        if (f.n === 0) return;
        this.process(f);
      },
      reset: () => {
        this.last.fill(0);
        this.apply(this.initial);
      },
      setParam: (name, value) => this.setParam(name, value),
      actions: this.actions(),
    };
  }

  private checkActive(list: readonly number[]): void {
    checkIndices(list, this.cols, this.what, "Active", this.unit);
  }

  /** Copies the active channels; the others as `mode` says. */
  private process(f: Frame): void {
    const { out, rows, cols, size, active, last, mode } = this;
    const n = f.n;
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
  }

  private setParam(name: string, value: unknown): void {
    if (name === "Active") {
      const list = value as number[] | undefined;
      if (list !== undefined) this.checkActive(list);
      this.initial = list;
      this.apply(list);
    } else if (name === "Inactive") {
      this.mode = value as Mode;
      this.describe();
    }
  }

  /** The status: how many channels are active, and which are not. */
  private describe(): void {
    const { cols, active, mode } = this;
    let n = 0;
    const off: number[] = [];
    for (let c = 0; c < cols; c++) {
      if (active[c]) n++;
      else off.push(c);
    }
    const shown = off.length > 12 ? `${off.slice(0, 12).join(", ")}, …` : off.join(", ");
    const verb = mode === "zero" ? "zeroed" : mode === "hold" ? "held" : "NaN";
    this.ctx.setText(
      off.length === 0
        ? `all ${cols} channels active`
        : `${n}/${cols} channels active (${shown} ${verb})`,
    );
  }

  /** Activates exactly `list` (undefined: every channel). */
  private apply(list: readonly number[] | undefined): void {
    const active = this.active;
    if (list === undefined) active.fill(1);
    else {
      active.fill(0);
      for (const c of list) active[c] = 1;
    }
    this.describe();
  }

  /** An action's argument: a channel index or a list of them. */
  private channels(arg: unknown): number[] {
    return indexListArg(arg, this.cols, `a channel of ${this.what} (or a list of them)`);
  }

  /** After an action: updates the status and returns the active channels. */
  private done(): string {
    this.describe();
    const on: number[] = [];
    for (let c = 0; c < this.cols; c++) if (this.active[c]) on.push(c);
    return `active channels: ${on.length === 0 ? "none" : on.join(", ")}`;
  }

  private actions(): Record<string, BlockAction> {
    const active = this.active;
    return {
      activate: {
        label: "Activate",
        description: "Let these channels pass (an index or a list)",
        run: (arg) => {
          for (const c of this.channels(arg)) active[c] = 1;
          return this.done();
        },
      },
      deactivate: {
        label: "Deactivate",
        description: "Replace these channels (an index or a list) as Inactive says",
        run: (arg) => {
          for (const c of this.channels(arg)) active[c] = 0;
          return this.done();
        },
      },
      toggle: {
        label: "Toggle",
        description: "Switch these channels (an index or a list) on or off",
        run: (arg) => {
          for (const c of new Set(this.channels(arg))) active[c] = active[c] ? 0 : 1;
          return this.done();
        },
      },
      all: {
        label: "All",
        description: "Activate every channel",
        run: () => {
          active.fill(1);
          return this.done();
        },
      },
      none: {
        label: "None",
        description: "Deactivate every channel",
        run: () => {
          active.fill(0);
          return this.done();
        },
      },
    };
  }
}
