/**
 * The virtual clock driver: jumps from wake-up to wake-up — the times a real-time worker that is
 * never late would wake, batching included — and runs everything that follows to quiescence, as
 * fast as the CPU allows. Same input, same output, byte for byte. Time does not advance while a
 * block waits for results from outside the engine (`ctx.setAwaiting`, e.g. Python calls): the
 * driver returns "waiting", and the host calls it again once `rt.onWake` says they arrived.
 */
import type { VirtualClock } from "../clock";
import type { Runtime } from "./runtime";

export type VirtualStop = "until" | "finished" | "yield" | "waiting";

/**
 * Runs `rt` on `clock` until virtual time `until` (inclusive), until every finite source has
 * finished, until `wallBudgetMs` of real time has passed (then returns "yield": call again), or
 * until a block waits for results from outside (then returns "waiting": call again when
 * `rt.awaiting` is back to 0, which `rt.onWake` reports).
 */
export function runVirtual(
  rt: Runtime,
  clock: VirtualClock,
  until: number,
  wallBudgetMs = Infinity,
): VirtualStop {
  const wallStart = performance.now();
  let i = 0;
  for (;;) {
    rt.dispatch();
    if (rt.awaiting > 0) return "waiting";
    if (rt.finished) return "finished";
    let next = rt.nextDeadline();
    if (!(next <= until)) {
      // A batch that would wait past the end: its ticks due by then go out at the end.
      if (rt.scheduler.nextDeadline() <= until) next = until;
      else {
        if (until > clock.t && Number.isFinite(until)) clock.t = until;
        return "until";
      }
    }
    if (next > clock.t) clock.t = next;
    rt.fireDue(clock.t);
    if ((++i & 255) === 0 && performance.now() - wallStart > wallBudgetMs) {
      rt.dispatch();
      return rt.awaiting > 0 ? "waiting" : "yield";
    }
  }
}
