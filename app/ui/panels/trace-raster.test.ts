import { describe, expect, test } from "vitest";
import { rasterTraces, rgbaWord, traceScratch, type TraceImage } from "./trace-raster";

function image(width: number, height: number): TraceImage {
  return { width, height, words: new Uint32Array(width * height) };
}

/** Rows coloured `word` in column k (top to bottom). */
function column(img: TraceImage, k: number, word: number): number[] {
  const rows: number[] = [];
  for (let r = 0; r < img.height; r++) if (img.words[r * img.width + k] === word) rows.push(r);
  return rows;
}

const RED = rgbaWord(255, 0, 0);
const BLUE = rgbaWord(0, 0, 255);

describe("rasterTraces", () => {
  test("a constant line is one row across the whole width", () => {
    const img = image(10, 11);
    const xs = Float64Array.from([0, 5, 10]);
    rasterTraces(
      img,
      traceScratch(10),
      xs,
      [Float64Array.from([0.5, 0.5, 0.5])],
      [RED],
      0,
      10,
      0,
      1,
    );
    for (let k = 0; k < 10; k++) expect(column(img, k, RED), `column ${k}`).toEqual([5]);
    expect(img.words.filter((w) => w !== 0).length).toBe(10);
  });

  test("a steep segment fills the rows it crosses in each column, without gaps", () => {
    const img = image(4, 9);
    // From the bottom (y = 0, row 8) at x = 0 to the top (y = 1, row 0) at x = 4.
    rasterTraces(
      img,
      traceScratch(4),
      Float64Array.from([0, 4]),
      [Float64Array.from([0, 1])],
      [RED],
      0,
      4,
      0,
      1,
    );
    expect(column(img, 0, RED)).toEqual([6, 7, 8]);
    expect(column(img, 1, RED)).toEqual([4, 5, 6]);
    expect(column(img, 2, RED)).toEqual([2, 3, 4]);
    expect(column(img, 3, RED)).toEqual([0, 1, 2]);
  });

  test("many samples in one column draw their min-max run; NaN leaves a gap", () => {
    const img = image(4, 11);
    const xs = Float64Array.from([0.1, 0.3, 0.5, 0.7, 2.5, 3.5]);
    const ys = Float64Array.from([0.2, 0.8, 0.4, 0.5, NaN, 0.5]);
    rasterTraces(img, traceScratch(4), xs, [ys], [RED], 0, 4, 0, 1);
    expect(column(img, 0, RED)).toEqual([2, 3, 4, 5, 6, 7, 8]);
    expect(column(img, 1, RED)).toEqual([]); // the segment into the NaN is not drawn
    expect(column(img, 3, RED)).toEqual([5]); // a lone point after the gap
  });

  test("later channels are drawn over earlier ones; out-of-range values are clipped", () => {
    const img = image(3, 5);
    const xs = Float64Array.from([0, 3]);
    rasterTraces(
      img,
      traceScratch(3),
      xs,
      [Float64Array.from([0.5, 0.5]), Float64Array.from([0.5, 0.5]), Float64Array.from([5, 5])],
      [RED, BLUE, RED],
      0,
      3,
      0,
      1,
    );
    for (let k = 0; k < 3; k++) expect(column(img, k, BLUE)).toEqual([2]);
    expect(img.words.filter((w) => w === RED).length).toBe(0);
  });

  test("points outside the x range only draw the part of their segment inside it", () => {
    const img = image(10, 3);
    const xs = Float64Array.from([-10, 5, 20]);
    rasterTraces(img, traceScratch(10), xs, [Float64Array.from([0, 0, 0])], [RED], 0, 10, 0, 1);
    for (let k = 0; k < 10; k++) expect(column(img, k, RED)).toEqual([2]);
  });

  test("the image is cleared first; an empty range draws nothing", () => {
    const img = image(2, 2);
    img.words.fill(7);
    rasterTraces(img, traceScratch(2), new Float64Array(0), [], [], 0, 1, 1, 1);
    expect(Array.from(img.words)).toEqual([0, 0, 0, 0]);
  });
});
