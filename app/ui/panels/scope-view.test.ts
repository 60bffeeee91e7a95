import { describe, expect, test } from "vitest";
import {
  clampRight,
  indexRange,
  lane,
  nearestIndex,
  panRange,
  visibleCsv,
  zoomRange,
} from "./scope-view";

describe("the scope's view arithmetic", () => {
  test("zoom keeps the anchor where it is; pan moves both ends", () => {
    expect(zoomRange([0, 10], 0.5, 4)).toEqual([2, 7]);
    expect(zoomRange([0, 10], 2, 10)).toEqual([-10, 10]);
    expect(zoomRange([0, 10], NaN, 3)).toEqual([0, 10]);
    expect(panRange([1, 3], -0.5)).toEqual([0.5, 2.5]);
  });

  test("a held right edge stays over the data", () => {
    expect(clampRight(20, 5, 0, 12)).toBe(12);
    expect(clampRight(2, 5, 0, 12)).toBe(5);
    expect(clampRight(8, 5, 0, 12)).toBe(8);
    // Less data than the span: the newest sample is the right edge.
    expect(clampRight(1, 5, 0, 3)).toBe(3);
  });

  test("stacked lanes tile the height without gaps", () => {
    const bands = Array.from({ length: 3 }, (_, k) => lane(k, 3, 100));
    expect(bands).toEqual([
      { top: 0, height: 33 },
      { top: 33, height: 34 },
      { top: 67, height: 33 },
    ]);
  });

  test("the sample nearest the cursor, and the samples in a range", () => {
    const t = [0, 0.1, 0.2, 0.3];
    expect(nearestIndex(t, 0.14)).toBe(1);
    expect(nearestIndex(t, 0.16)).toBe(2);
    expect(nearestIndex(t, -1)).toBe(0);
    expect(nearestIndex(t, 9)).toBe(3);
    expect(nearestIndex([], 1)).toBe(-1);
    expect(indexRange(t, 0.05, 0.25)).toEqual([1, 3]);
    expect(indexRange(t, 1, 2)).toEqual([4, 4]);
  });

  test("CSV of the visible window: named header, the rows inside [x0, x1], NaN empty", () => {
    const csv = visibleCsv(
      [0, 0.5, 1, 1.5],
      [
        [1, 2, NaN, 4],
        [0.25, -3, 1e-7, 8],
      ],
      ["EMG 1", 'a "quoted", name'],
      0.5,
      1,
    );
    expect(csv).toBe('time_s,EMG 1,"a ""quoted"", name"\n0.5,2,-3\n1,,1e-7\n');
  });
});
