/**
 * Times between the pipeline clock (UNIX seconds, or virtual seconds) and LSL's clock (liblsl's
 * `lsl_local_clock`, a monotonic clock of this machine), and a sender's LSL clock mapped onto ours
 * with liblsl's time correction. Pure: the blocks read the clocks and hand the numbers in.
 */

/** One bracketed reading: LSL's clock before, the pipeline clock, LSL's clock after. */
export interface ClockReading {
  lslBefore: number;
  pipeline: number;
  lslAfter: number;
}

/**
 * The offset `lsl - pipeline` from bracketed readings: the tightest bracket wins (the least
 * disturbed by preemption), its midpoint against the pipeline reading; `uncertainty` is half that
 * bracket. Undefined when there is no reading.
 */
export function bracketOffset(
  readings: readonly ClockReading[],
): { offset: number; uncertainty: number } | undefined {
  let best: ClockReading | undefined;
  for (const r of readings) {
    if (!best || r.lslAfter - r.lslBefore < best.lslAfter - best.lslBefore) best = r;
  }
  if (!best) return undefined;
  return {
    offset: (best.lslBefore + best.lslAfter) / 2 - best.pipeline,
    uncertainty: (best.lslAfter - best.lslBefore) / 2,
  };
}

/** How far a new measurement may differ from the offset in use before it replaces it, s. */
export const CLOCK_STEP_S = 0.0005;

/**
 * `lsl = pipeline + offset`. The offset is measured at start and checked again now and then; a
 * new measurement replaces it only when it differs by more than CLOCK_STEP_S (the two clocks tick
 * at the same rate in real time, so small differences are reading noise, not drift) and the change
 * is counted as a step.
 */
export class ClockMap {
  offset = Number.NaN;
  uncertainty = Number.POSITIVE_INFINITY;
  steps = 0;

  get known(): boolean {
    return Number.isFinite(this.offset);
  }

  /** Takes a measurement (from `bracketOffset`); true when the offset in use changed. */
  adopt(m: { offset: number; uncertainty: number } | undefined): boolean {
    if (!m) return false;
    if (!this.known) {
      this.offset = m.offset;
      this.uncertainty = m.uncertainty;
      return true;
    }
    if (Math.abs(m.offset - this.offset) <= Math.max(CLOCK_STEP_S, m.uncertainty)) return false;
    this.offset = m.offset;
    this.uncertainty = m.uncertainty;
    this.steps++;
    return true;
  }

  toLsl(pipelineT: number): number {
    return pipelineT + this.offset;
  }

  fromLsl(lslT: number): number {
    return lslT - this.offset;
  }
}

/** Reads the clocks `rounds` times and measures the offset (see `bracketOffset`). */
export function measureOffset(
  pipelineNow: () => number,
  lslNow: () => number,
  rounds = 7,
): { offset: number; uncertainty: number } | undefined {
  const readings: ClockReading[] = [];
  for (let i = 0; i < rounds; i++) {
    const lslBefore = lslNow();
    const pipeline = pipelineNow();
    const lslAfter = lslNow();
    readings.push({ lslBefore, pipeline, lslAfter });
  }
  return bracketOffset(readings);
}

/**
 * A sender's timestamp on the pipeline clock: `remote + correction` is this machine's LSL time
 * (liblsl's time correction: the sender's clock offset), then back to the pipeline clock.
 */
export function senderToPipeline(remoteT: number, correction: number, map: ClockMap): number {
  return map.fromLsl(remoteT + correction);
}

/**
 * Latency of arriving samples (arrival on the pipeline clock minus their mapped timestamp), as a
 * running mean and standard deviation (the jitter) over everything since the last reset
 * (Welford's update), with the extremes.
 */
export class LatencyStats {
  n = 0;
  mean = 0;
  private m2 = 0;
  min = Number.POSITIVE_INFINITY;
  max = Number.NEGATIVE_INFINITY;

  add(latency: number): void {
    this.n++;
    const d = latency - this.mean;
    this.mean += d / this.n;
    this.m2 += d * (latency - this.mean);
    if (latency < this.min) this.min = latency;
    if (latency > this.max) this.max = latency;
  }

  /** Standard deviation (0 with fewer than two values). */
  get jitter(): number {
    return this.n > 1 ? Math.sqrt(this.m2 / (this.n - 1)) : 0;
  }

  reset(): void {
    this.n = 0;
    this.mean = 0;
    this.m2 = 0;
    this.min = Number.POSITIVE_INFINITY;
    this.max = Number.NEGATIVE_INFINITY;
  }
}
