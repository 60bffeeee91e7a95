/**
 * The Status tab's "Latency" figure: the engine's mean of (emission time − timestamp of the
 * newest event of each frame), never shown below zero.
 *
 * A source paced by a timer stamps its events with the tick's deadline, and the loop fires a tick
 * up to a few microseconds before it (the scheduler's early tolerance: 2 µs, more on the coarse
 * loop) while the page's clock moves in steps of 5 µs (100 µs without cross-origin isolation). So
 * the block that emits in its own tick reads a few microseconds *before* its own timestamps: a
 * "latency" of −5 µs that is an artefact of the clock's resolution, not data from the future.
 * Within a millisecond below zero it reads as 0; further below, the events' timestamps really run
 * ahead of the clock (a device or file clock not on the pipeline's) and the figure says that
 * instead of a negative latency.
 */

/** How far below zero still reads as the clock's resolution, ms. */
export const RESOLUTION_MS = 1;

/** A duration to the precision that matters: "12 ms", "1.25 ms", "350 µs". */
export function durationText(ms: number): string {
  if (ms >= 100) return `${ms.toFixed(0)} ms`;
  if (ms >= 1) return `${ms.toFixed(2)} ms`;
  return `${(ms * 1000).toFixed(0)} µs`;
}

/** The latency figure: never negative (see above); "—" before any measurement. */
export function latencyText(latencyMs: number): string {
  if (!Number.isFinite(latencyMs)) return "—";
  if (latencyMs >= 0) return durationText(latencyMs);
  if (latencyMs > -RESOLUTION_MS) return durationText(0);
  return `0 (timestamps ${durationText(-latencyMs)} ahead of the clock)`;
}
