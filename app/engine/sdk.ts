/**
 * The block SDK: what a block written outside this repository imports (`import { defineBlock, z }
 * from "mosaic/sdk"`). The same API the built-in blocks use (app/engine/block.ts), nothing of the
 * engine's internals. When MOSAIC loads a user's block module (app/host/user-blocks.ts) it hands
 * the module this very object, so a user block's `z` schemas, `BlockConfigError` and frames are the
 * engine's own (docs/writing-blocks.md).
 */
import { z } from "zod";

export { z };
export {
  defineBlock,
  outputNames,
  portMetaProblem,
  type AnyBlockDefinition,
  type BlockAction,
  type BlockCategory,
  type BlockContext,
  type BlockDefinition,
  type BlockInstance,
  type BlockView,
  type ElectrodeGrid,
  type FileReadHandle,
  type FileWriteHandle,
  type InputInfo,
  type InputSpec,
  type OutputPort,
  type PortMeta,
  type Resources,
  type TimerHandle,
} from "./block";
export { BlockConfigError } from "./diagnostics";
export {
  EMPTY_SHAPE,
  Frame,
  formatShape,
  matrixShape,
  sameShape,
  shapeSize,
  vectorShape,
  type Shape,
} from "./frame";
export {
  LegacyParamsError,
  legacyInteger,
  legacyNumber,
  legacyPair,
  legacyVector,
} from "./pipeline/legacy";
export { RUST_BLOCK_ABI_VERSION, rustBlock, type RustBlockOptions } from "./rust-block";
export type { CatchUp, TickCallback } from "./runtime/scheduler";

/** The SDK's version: a user module may check it; it grows when the API grows. */
export const SDK_VERSION = 1;

/** The categories a block may name (the palette's groups). */
export const BLOCK_CATEGORIES = [
  "Timing",
  "Sources",
  "Signal processing",
  "Features",
  "Kinematics",
  "Flow control",
  "Learning",
  "Control",
  "Communication",
  "Devices",
  "Recording",
  "Testing",
] as const;
