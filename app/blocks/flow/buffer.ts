import { z } from "zod";
import { defineBlock } from "../../engine";
import { BufferRun } from "./buffer-run";

/**
 * What a Buffer offers by its name (shared/named.ts, kind "Buffer") to the blocks that MOSAIC let
 * read it by name (BatchPredictor, PythonNetLearning): its rows, read on request.
 */
export interface BufferRows {
  /** T, values per target. */
  readonly targetWidth: number;
  /** D, values per data row. */
  readonly dataWidth: number;
  /** Rows stored now. */
  rows(): number;
  /** The stored rows [target…, data…], rows × (T + D) values; read before the next event. */
  values(): Float64Array;
  /** Calls `fn` whenever a cluster with rows closes (recording stops or changes target). */
  onClusterClosed(fn: () => void): () => void;
}

export const BufferBlock = defineBlock({
  type: "Buffer",
  category: "Flow control",
  summary:
    "Records (target, data) pairs between start and stop triggers, as labelled clusters for batch learning.",
  help:
    "Segments a data stream into labelled clusters for batch machine learning (paper III-F, " +
    "III-G). Inputs are `[Trigger, Data]`. As in MOSAIC, a data input written `-Data` is " +
    "subscribed only while recording (nothing is delivered in between); written `Data`, it stays " +
    "subscribed and the Buffer ignores data outside recording. Trigger protocol: " +
    "a trigger event whose values are a target vector [1, T] starts recording a cluster " +
    "labelled with that target (a different target closes the current cluster and starts a new " +
    "one; the same target again continues it); an event whose values are all NaN stops " +
    "recording; an event with only some NaN values is ignored with a warning. While recording, " +
    "every data event (its D values, row by row for a matrix) is stored as one row `[target…, " +
    "data…]` with the event's timestamp; data outside recording is ignored, so the data input " +
    "may stay subscribed. Actions: `start` (a target as a list of T numbers, or a label index k: " +
    "[k] when T = 1, the one-hot vector e_k otherwise), `stop`, `clear`, `save` (a file name, " +
    "default `<block>.csv`, relative to the pipeline file: one CSV line `target…,data…` per row, " +
    "no header, as MOSAIC's save button wrote), `inspect` (clusters and rows per target) and " +
    "`emit`, which sends every stored row at once, as one frame of [1, T + D] events on the " +
    "`pairs` output (how a BatchPredictor is trained). With `Stream: true` rows are also sent on " +
    "`pairs` as they are recorded. Memory is bounded by `MaxRows`: when it is full, further rows " +
    "are dropped and counted, and the status says so until you save, emit or clear. Clusters " +
    "that received no rows are not kept. Blocks that MOSAIC let read a Buffer by its name " +
    "(a BatchPredictor or PythonNetLearning written `[bufferName, …]`) read its rows when they " +
    "build their model, on the same worker.",
  params: z.strictObject({
    Stream: z
      .boolean()
      .default(false)
      .describe(
        "Also send every row on the pairs output as it is recorded (can be changed while running)",
      ),
    MaxRows: z
      .number()
      .int()
      .min(1)
      .max(10_000_000)
      .default(100_000)
      .describe(
        "Most rows kept (bounded memory: rows × (T + D) × 8 bytes, at most 1 GiB); rows beyond " +
          "are dropped and counted",
      ),
  }),
  legacyParams: () => ({}),
  legacyForm: "no params: `{ Type: Buffer, Inputs: [Trigger, -Data] }`",
  inputs: { min: 2, max: 2, labels: ["trigger", "data"] },
  outputs: ["pairs"],
  live: ["Stream"],
  views: ["label"],
  panel: "Clusters and rows per target, with start, stop, clear, save, emit and inspect buttons.",
  create(ctx, p) {
    return new BufferRun(ctx, p).instance();
  },
});
