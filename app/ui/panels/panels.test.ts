import { describe, expect, it } from "vitest";
import {
  Smoother,
  StickyRange,
  cellOf,
  channelColor,
  channelLabel,
  defaultChannels,
  finiteExtent,
  formatChannelSelection,
  formatValue,
  gridChoices,
  inferGrid,
  niceTicks,
  parseChannelSelection,
} from "./channels";
import { ScopeBuffer } from "./scope-buffer";
import { StatusHistory } from "./status-history";

describe("channel selection", () => {
  it("parses lists and ranges, and says what is wrong", () => {
    expect(parseChannelSelection("0-3, 7; 5", 8)).toEqual({
      ok: true,
      channels: [0, 1, 2, 3, 5, 7],
    });
    expect(parseChannelSelection("all", 3)).toEqual({ ok: true, channels: [0, 1, 2] });
    expect(parseChannelSelection("", 3)).toEqual({ ok: true, channels: [] });
    expect(parseChannelSelection("2-1", 3)).toMatchObject({ ok: false });
    expect(parseChannelSelection("8", 8)).toEqual({
      ok: false,
      error: "channel 8 does not exist (channels are 0–7)",
    });
    expect(parseChannelSelection("a", 8)).toMatchObject({ ok: false });
  });
  it("formats runs as ranges", () => {
    expect(formatChannelSelection([0, 1, 2, 3, 5, 7, 8])).toBe("0-3, 5, 7-8");
    expect(formatChannelSelection([])).toBe("");
  });
  it("plots at most 16 channels by default", () => {
    expect(defaultChannels(8)).toHaveLength(8);
    expect(defaultChannels(256)).toEqual([...Array(16).keys()]);
  });
  it("names channels by the engine's labels when given", () => {
    expect(channelLabel({ labels: ["MAV 0", "ZC 0"] }, 1)).toBe("ZC 0");
    expect(channelLabel({}, 3)).toBe("3");
  });
  it("gives distinct colours", () => {
    const c = new Set([...Array(64).keys()].map(channelColor));
    expect(c.size).toBe(64);
  });
});

describe("electrode grids", () => {
  it("infers near-square grids", () => {
    expect(inferGrid(8)).toEqual({ rows: 2, cols: 4 });
    expect(inferGrid(32)).toEqual({ rows: 4, cols: 8 });
    expect(inferGrid(64)).toEqual({ rows: 8, cols: 8 });
    expect(inferGrid(256)).toEqual({ rows: 16, cols: 16 });
    expect(inferGrid(7)).toEqual({ rows: 3, cols: 3 });
    expect(inferGrid(1)).toEqual({ rows: 1, cols: 1 });
  });
  it("lists exact grids and places channels row- or column-major", () => {
    expect(gridChoices(8)).toEqual([
      { rows: 1, cols: 8 },
      { rows: 2, cols: 4 },
      { rows: 4, cols: 2 },
      { rows: 8, cols: 1 },
    ]);
    expect(cellOf(5, 4, 2, false)).toEqual([1, 1]);
    expect(cellOf(5, 4, 2, true)).toEqual([1, 2]);
  });
});

describe("numbers", () => {
  it("formats with 4 significant digits", () => {
    expect(formatValue(0.123456)).toBe("0.1235");
    expect(formatValue(-12.3456)).toBe("−12.35");
    expect(formatValue(1234.5)).toBe("1235");
    expect(formatValue(0)).toBe("0");
    expect(formatValue(1e-7)).toBe("1.000e−7");
    expect(formatValue(NaN)).toBe("NaN");
    expect(formatValue(Infinity)).toBe("∞");
  });
  it("finds finite extents and nice ticks", () => {
    expect(finiteExtent([3, NaN, -1, Infinity])).toEqual([-1, 3]);
    expect(finiteExtent([3, -1, 2])).toEqual([-1, 3]);
    expect(finiteExtent([])).toEqual([NaN, NaN]);
    expect(niceTicks(0, 1, 4)).toEqual([0, 0.25, 0.5, 0.75, 1]);
  });
  it("autoscales: widens at once, narrows slowly", () => {
    const r = new StickyRange(1, 0);
    expect(r.update(0, 10, 0)).toEqual([0, 10]);
    expect(r.update(-5, 5, 0.1)[0]).toBe(-5);
    const [, hi] = r.update(-5, 5, 0.1);
    expect(hi).toBeGreaterThan(5);
    expect(hi).toBeLessThan(10);
    for (let i = 0; i < 200; i++) r.update(-5, 5, 0.1);
    expect(r.hi).toBeCloseTo(5, 3);
    expect(r.update(NaN, NaN, 0.1)[1]).toBeCloseTo(5, 3);
    expect(new StickyRange().update(2, 2, 0)[0]).toBeLessThan(2);
  });
  it("smooths per channel by event time", () => {
    const s = new Smoother(2, "envelope", 0.1);
    s.push(0, Float64Array.of(-1, 2), 0);
    expect([...s.out]).toEqual([1, 2]);
    for (let i = 1; i <= 100; i++) s.push(i * 0.01, Float64Array.of(i % 2 ? -3 : 3, 0), 0);
    expect(s.out[0]).toBeCloseTo(3, 3);
    expect(s.out[1]).toBeLessThan(0.01);
    const latest = new Smoother(2);
    latest.push(0, Float64Array.of(9, 1, 2, 3), 2);
    expect([...latest.out]).toEqual([2, 3]);
  });
});

describe("ScopeBuffer", () => {
  const msg = (t0: number, n: number, cols: number, dt = 0.01) => {
    const t = new Float64Array(n);
    const v = new Float64Array(n * cols);
    for (let i = 0; i < n; i++) {
      t[i] = t0 + i * dt;
      for (let c = 0; c < cols; c++) v[i * cols + c] = i * 10 + c;
    }
    return { t, v };
  };

  it("keeps the newest samples contiguous and time-ordered across the wrap", () => {
    const b = new ScopeBuffer([1, 3], 16, 0.05, 16);
    const { t, v } = msg(1000, 40, 4);
    b.append(t, v, 1, 4);
    expect(b.count).toBe(16);
    const [x, y1, y3] = b.view(-Infinity);
    expect(x!.length).toBe(16);
    for (let i = 1; i < x!.length; i++) expect(x![i]!).toBeGreaterThan(x![i - 1]!);
    expect(x![15]).toBeCloseTo(0.39, 9);
    expect(y1![15]).toBe(391);
    expect(y3![0]).toBe(243);
  });

  it("views a time window with one sample before it", () => {
    const b = new ScopeBuffer([0], 100, 1);
    const { t, v } = msg(5, 50, 1);
    b.append(t, v, 1, 1);
    const [x] = b.view(0.2, 0.3);
    expect(x![0]).toBeCloseTo(0.19, 9);
    expect(x![x!.length - 1]).toBeCloseTo(0.31, 9);
    expect(b.newestX).toBeCloseTo(0.49, 9);
  });

  it("grows when the stream is faster than planned, and reuses its outer array", () => {
    const b = new ScopeBuffer([0], 16, 1, 1024);
    const first = b.view(-Infinity);
    const { t, v } = msg(0, 200, 1, 0.001);
    b.append(t, v, 1, 1);
    expect(b.capacity).toBeGreaterThanOrEqual(200);
    expect(b.count).toBe(200);
    const [x, y] = b.view(-Infinity);
    expect(x!.length).toBe(200);
    expect(y![199]).toBe(1990);
    for (let i = 1; i < 200; i++) expect(x![i]!).toBeGreaterThan(x![i - 1]!);
    expect(b.view(-Infinity)).toBe(first);
  });

  it("matrices: newest row, or all rows in time order", () => {
    // Two windows of 2 rows × 2 columns.
    const t = Float64Array.of(1, 2);
    const v = Float64Array.of(1, 2, 3, 4, 5, 6, 7, 8);
    const newest = new ScopeBuffer([0, 1], 16, 10);
    newest.append(t, v, 2, 2, "newest");
    expect([...newest.view(-Infinity)[1]!]).toEqual([3, 7]);
    const flat = new ScopeBuffer([1], 16, 10);
    flat.append(t, v, 2, 2, "flatten");
    const [x, y] = flat.view(-Infinity);
    expect([...y!]).toEqual([2, 4, 6, 8]);
    expect([...x!]).toEqual([0, 0, 0.5, 1]);
  });

  it("starts again when the clock goes back (a new run)", () => {
    const b = new ScopeBuffer([0], 16, 10);
    b.append(Float64Array.of(100, 101), Float64Array.of(1, 2), 1, 1);
    b.append(Float64Array.of(5), Float64Array.of(3), 1, 1);
    expect(b.count).toBe(1);
    expect(b.t0).toBe(5);
  });
});

describe("StatusHistory", () => {
  it("keeps the last minute of statuses and summarises it", () => {
    const h = new StatusHistory(60);
    for (let i = 0; i < 1500; i++) {
      h.push(
        i * 0.05,
        i < 1400 ? "ontime" : "lagging",
        100,
        0.1,
        i === 1499 ? 2 : 0.2,
        // A late batch a minute and a half ago (forgotten) and one 10 s ago.
        i === 100 ? 90 : i === 1300 ? 30 : 1.5,
      );
    }
    expect(h.count).toBe(1200);
    const s = h.summary();
    expect(s.fraction.lagging).toBeCloseTo(100 / 1200, 3);
    expect(s.fraction.ontime).toBeCloseTo(1100 / 1200, 3);
    expect(s.computeMaxMs).toBe(2);
    expect(s.delayMaxMs).toBe(30);
    expect(h.newestT).toBeCloseTo(1499 * 0.05, 6);
    const seen: string[] = [];
    h.forEach((_t, status) => seen.push(status));
    expect(seen).toHaveLength(1200);
    expect(seen[seen.length - 1]).toBe("lagging");
  });
});
