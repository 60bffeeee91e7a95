/**
 * Bounds of list params (issue 14, item 12): no schema accepts a list without a maximum, so a
 * pasted table or a runaway generator cannot make a block allocate without end. Each bound is far
 * above real use and is named in the error (zod: "Too big: expected array to have <=4096 items").
 * The loader also bounds a block's Params to 131 072 values in all (LOAD_LIMITS in
 * app/engine/pipeline/spec.ts).
 */

/** Values of one event: per-channel operands and gains, channel and column lists, a matrix row. */
export const MAX_CHANNELS = 65_536;
/** Coefficients of one filter: a 2-s FIR at 2 kHz (IIR orders stay far below). */
export const MAX_COEFFICIENTS = 4096;
/**
 * Things one block names or lists: degrees of freedom, rows of a matrix (outputs), features,
 * gestures and cue names, output ports and parts, per-input settings.
 */
export const MAX_ITEMS = 4096;
/** Steps of a played sequence. */
export const MAX_SEQUENCE = 100_000;
