/** FilePlayer: the `position` output (for the panel's Player view). */
import { vectorShape, type BlockContext, type Frame } from "../../engine";
import type { RowSource } from "./row-source";

/** Row of a played recording, for the `position` output: seconds, duration, row, rows. */
export interface PlayPosition {
  /** A frame for `n` positions, or null when nothing reads the output. */
  frame(n: number): Frame | null;
  put(f: Frame, e: number, t: number, row: number): void;
  emit(f: Frame, n: number): void;
  /** Emits the position of `row` (the next to play) now: after a seek or a restart. */
  now(row: number): void;
}

/** Declares the `position` output of `src` (computed only while something reads it). */
export function playPosition(ctx: BlockContext, src: RowSource): PlayPosition {
  const port = ctx.output(vectorShape(4), "position", {
    labels: ["seconds", "duration", "row", "rows"],
  });
  const first = src.hasTimes ? src.time(0) : NaN;
  let duration = NaN;
  if (src.hasTimes) {
    try {
      duration = src.lastTime() - first;
    } catch {
      // A streamed file whose end cannot be read yet: the duration stays unknown.
    }
  }
  const put = (f: Frame, e: number, t: number, row: number): void => {
    f.t[e] = t;
    const v = f.v;
    v[e * 4] = src.hasTimes ? src.time(row) - first : NaN;
    v[e * 4 + 1] = duration;
    v[e * 4 + 2] = row + 1;
    v[e * 4 + 3] = src.total ?? NaN;
  };
  return {
    frame: (n) => (port.idle ? null : port.frame(n)),
    put,
    emit(f, n) {
      f.n = n;
      port.emit(f);
    },
    now(row) {
      if (port.idle || !(src.fill(row + 1) > row)) return;
      const f = port.frame(1);
      put(f, 0, ctx.now(), row);
      port.emit(f);
    },
  };
}
