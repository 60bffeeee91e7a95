/**
 * The Status tab's "Latency" figure: the engine's mean of (emission time − timestamp of the
 * newest event of each frame), never shown below zero.
 *
 * Why it read negative ("Latency −5 µs", up to about −0.1 ms in the demo): a source paced by a
 * timer (the Timer, and the Emg simulator it drives) stamps its events with the tick's deadline,
 * and the real-time loop fires ticks a little *before* their deadline on purpose: it wakes early
 * by its learned wake-up overshoot and fires what is due within that margin (the scheduler's
 * early tolerance, at most 0.2 ms, runtime/loop.ts) rather than sleep again; the page's clock
 * moves in 5 µs steps besides (100 µs without cross-origin isolation). So a source emitting in
 * its own tick is up to ~0.2 ms before its own timestamps, and the mean over a telemetry window
 * can fall below zero. No data comes from the future: within a millisecond below zero the figure
 * reads 0. Further below, the events' timestamps really run ahead of the pipeline's clock (a
 * device or file clock not on it) and the figure says that instead of a negative latency.
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
