/**
 * Create-time checks shared by blocks: what kind of input sits at a position of `Inputs`, with
 * messages that name the input, what it is and what the block expected (thrown as
 * BlockConfigError so the loader positions them on the block).
 */
import {
  BlockConfigError,
  closest,
  formatShape,
  type BlockContext,
  type InputInfo,
  type Shape,
} from "../../engine";

export interface SignalInput {
  info: InputInfo;
  shape: Shape;
  /** Values per event (rows × cols). */
  size: number;
}

/** `'Emg'`, as inputs are named in messages. */
export const inputName = (info: InputInfo): string => `'${info.source}'`;

/** The input at `index` must carry values (not a timer) and have a known shape. */
export function signalInput(ctx: BlockContext, index: number, param?: string): SignalInput {
  const info = ctx.inputs[index];
  if (!info) {
    throw new BlockConfigError(
      `${ctx.type} needs an input at position ${index + 1} of Inputs`,
      param,
    );
  }
  if (info.isTimer) {
    throw new BlockConfigError(
      `input ${inputName(info)} is a timer (its events carry no values); ${ctx.type} needs a signal there`,
      param,
    );
  }
  const shape = info.shape;
  if (shape === null) {
    throw new BlockConfigError(
      `the shape of input ${inputName(info)} is unknown (it is created later inside a feedback cycle); ` +
        `${ctx.type} needs to know its input shape when it is created`,
      param,
    );
  }
  const size = shape.rows * shape.cols;
  if (size === 0) {
    throw new BlockConfigError(
      `input ${inputName(info)} has shape ${formatShape(shape)}, which carries no values`,
      param,
    );
  }
  return { info, shape, size };
}

/** Like `signalInput`, and the value must be a vector [1, C]. */
export function vectorInput(ctx: BlockContext, index: number, param?: string): SignalInput {
  const s = signalInput(ctx, index, param);
  if (s.shape.rows !== 1) {
    throw new BlockConfigError(
      `input ${inputName(s.info)} has shape ${formatShape(s.shape)} (a matrix); ${ctx.type} needs a vector [1, C]`,
      param,
    );
  }
  return s;
}

/** The input at `index` must be a timer. */
export function timerInput(ctx: BlockContext, index: number, param?: string): InputInfo {
  const info = ctx.inputs[index];
  if (!info) throw new BlockConfigError(`${ctx.type} needs a timer input`, param);
  if (!info.isTimer) {
    throw new BlockConfigError(
      `input ${inputName(info)} is not a timer; ${ctx.type} is paced by a timer input ` +
        "(ScheduledTimer or DecimatorTimer)",
      param,
    );
  }
  return info;
}

/**
 * Finds the input named `name` (a block name, or `Block.port` as written in Inputs); throws a
 * BlockConfigError listing the inputs and suggesting the closest one otherwise.
 */
export function findInput(ctx: BlockContext, name: string, param: string): InputInfo {
  const hit = ctx.inputs.find((i) => i.source === name) ?? ctx.inputs.find((i) => i.block === name);
  if (hit) return hit;
  const names = ctx.inputs.map((i) => i.source);
  const suggestion = closest(name, names);
  throw new BlockConfigError(
    `${param} '${name}' is not one of its inputs (${names.join(", ")})` +
      (suggestion !== undefined ? `; did you mean '${suggestion}'?` : ""),
    param,
  );
}

/** Checks 0-based `indices` against a width; names the first bad one and the valid range. */
export function checkIndices(
  indices: readonly number[],
  width: number,
  what: string,
  param: string,
  unit: "channel" | "column" = "channel",
): void {
  for (const i of indices) {
    if (i >= width) {
      throw new BlockConfigError(
        `index ${i} is out of range for ${what} with ${width} ${unit}${width === 1 ? "" : "s"} ` +
          `(valid: 0–${width - 1})`,
        param,
      );
    }
  }
}
