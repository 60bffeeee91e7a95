/**
 * FilePlayer: the checks of a recording when the pipeline loads, and what original timing needs
 * from it (the first row's time, the median interval between rows, a loop's length).
 */
import { BlockConfigError, type BlockContext } from "../../engine";
import { MAX_TIMER_HZ } from "../timing/scheduled-timer";
import { FILE_LIMITS } from "./delimited-text";
import { disorderText, type FilePlayerParams } from "./file-player-rows";
import type { RowSource } from "./row-source";

/** What original timing plays by; with a timer input, t0 0, median NaN and span 0. */
export interface PlayTiming {
  /** The first row's time, s. */
  t0: number;
  /** The median interval between the rows checked at load, s. */
  median: number;
  /** A loop's length (last row − first + one median interval), s; 0 until Loop needs it. */
  span: number;
}

/**
 * Reads the rows a load checks (all of a whole file) and, without a timer input, the timing they
 * are played by: the recording's errors as BlockConfigErrors on the param to change. Sets the
 * desired rate (Speed / median interval) unless the file declares one.
 */
export function loadTiming(
  ctx: BlockContext,
  p: FilePlayerParams,
  timed: boolean,
  src: RowSource,
): PlayTiming {
  const first = checkFirstRows(src, p.File);
  if (timed) return { t0: 0, median: NaN, span: 0 };
  if (!src.hasTimes) {
    throw new BlockConfigError(
      `'${p.File}' has no time column, so it cannot be played at its original timing; either ` +
        "give the FilePlayer a timer input (one row per tick) or name the time column with " +
        "TimeColumn",
      "TimeColumn",
    );
  }
  if (first < 2) {
    throw new BlockConfigError(
      `'${p.File}' has only one row; original timing needs at least two rows (or a timer input)`,
      "File",
    );
  }
  const median = medianInterval(src, first, p.File);
  const rowHz = p.Speed / median;
  const tooFast = speedProblem(p.Speed, median, p.File);
  if (tooFast !== undefined) throw new BlockConfigError(tooFast, p.Speed !== 1 ? "Speed" : "File");
  const t0 = src.time(0);
  // Only a loop needs the last row (read from the file's end when it streams).
  const span = p.Loop ? loopSpan(src, t0, median) : 0;
  if (ctx.declaredRate === undefined) ctx.setDesiredRate(rowHz);
  return { t0, median, span };
}

/** The first rows must be readable when the pipeline loads (all of a whole file): how many. */
function checkFirstRows(src: RowSource, file: string): number {
  const first = src.fill(src.total ?? FILE_LIMITS.firstRows);
  if (src.error !== undefined && first < FILE_LIMITS.firstRows) {
    throw new BlockConfigError(src.error, "File");
  }
  if (first === 0) throw new BlockConfigError(`'${file}' has a header but no data rows`, "File");
  return first;
}

/** The median interval between the `first` rows checked at load; refuses times that go back or stand still. */
function medianInterval(src: RowSource, first: number, file: string): number {
  const dts = new Float64Array(first - 1);
  for (let i = 1; i < first; i++) {
    const dt = src.time(i) - src.time(i - 1);
    if (!(dt >= 0)) {
      throw new BlockConfigError(
        disorderText(src.line(i), file, src.time(i), src.time(i - 1)),
        "TimeColumn",
      );
    }
    dts[i - 1] = dt;
  }
  dts.sort();
  const median = sortedMedian(dts);
  if (!(median > 0)) {
    throw new BlockConfigError(
      `the median interval between rows of '${file}' is 0 (repeated times); original ` +
        "timing needs increasing times",
      "TimeColumn",
    );
  }
  return median;
}

/** The median of sorted values (the mean of the middle two of an even count); NaN when empty. */
export function sortedMedian(v: Float64Array): number {
  const m = v.length;
  return m % 2 === 1 ? v[(m - 1) / 2]! : (v[m / 2 - 1]! + v[m / 2]!) / 2;
}

/** A loop's length: from the first row to one median interval after the last. */
export const loopSpan = (src: RowSource, t0: number, median: number): number =>
  src.lastTime() - t0 + median;

/** Why `speed` cannot play rows `median` seconds apart (faster than the engine paces), or undefined. */
export function speedProblem(speed: number, median: number, file: string): string | undefined {
  const rowHz = speed / median;
  if (!(rowHz > MAX_TIMER_HZ)) return undefined;
  const fileHz = Number((1 / median).toPrecision(6));
  return speed !== 1
    ? `at Speed ${speed} the rows of '${file}' (${fileHz} Hz) would play at ` +
        `${Number(rowHz.toPrecision(6))} Hz, above the fastest the engine paces, ` +
        `${MAX_TIMER_HZ} Hz: lower Speed`
    : `the rows of '${file}' come at ${fileHz} Hz, above the fastest the engine paces, ` +
        `${MAX_TIMER_HZ} Hz: play it with a timer input (one row per tick) or resample it`;
}
