import { describe, expect, test } from "vitest";
import {
  bracketOffset,
  CLOCK_STEP_S,
  ClockMap,
  LatencyStats,
  measureOffset,
  senderToPipeline,
} from "./clock-map";
import { streamPredicate, toIntegerFormat, xpathLiteral } from "./lsl-common";
import { markerCode, markerText } from "./lsl-markers";
import { markerValue } from "./lsl-marker-inlet";

describe("clock mapping between the pipeline and LSL", () => {
  test("the tightest bracket gives the offset, half its width the uncertainty", () => {
    const m = bracketOffset([
      { lslBefore: 100.0, pipeline: 1000.004, lslAfter: 100.01 },
      { lslBefore: 100.02, pipeline: 1000.0205, lslAfter: 100.021 },
      { lslBefore: 100.03, pipeline: 1000.0, lslAfter: 100.06 },
    ])!;
    expect(m.offset).toBeCloseTo(100.0205 - 1000.0205, 12);
    expect(m.uncertainty).toBeCloseTo(0.0005, 12);
    expect(bracketOffset([])).toBeUndefined();
  });

  test("measured against two clocks with a known offset and no jitter, it is exact", () => {
    // A pipeline clock at 1.7e9 s (UNIX time) and LSL's at 5000 s, each read advancing 1 µs.
    let tick = 0;
    const lsl = () => 5000 + tick++ * 1e-6;
    const pipeline = () => 1.7e9 + tick++ * 1e-6;
    const m = measureOffset(pipeline, lsl, 5)!;
    expect(m.offset).toBeCloseTo(5000 - 1.7e9, 5);
    expect(m.uncertainty).toBeCloseTo(1e-6, 9);
  });

  test("a ClockMap maps both ways and round-trips exactly for times of a run", () => {
    const map = new ClockMap();
    expect(map.known).toBe(false);
    expect(map.adopt({ offset: -1_699_999_000.25, uncertainty: 1e-6 })).toBe(true);
    for (const t of [1_700_000_000, 1_700_000_000.0005, 1_700_003_600.123]) {
      const l = map.toLsl(t);
      expect(l).toBeCloseTo(t - 1_699_999_000.25, 6);
      expect(map.fromLsl(l)).toBeCloseTo(t, 6);
    }
  });

  test("re-measurements within the noise keep the offset; a real step replaces it and is counted", () => {
    const map = new ClockMap();
    map.adopt({ offset: 10, uncertainty: 1e-5 });
    expect(map.adopt({ offset: 10 + CLOCK_STEP_S / 2, uncertainty: 1e-5 })).toBe(false);
    expect(map.offset).toBe(10);
    expect(map.adopt(undefined)).toBe(false);
    expect(map.adopt({ offset: 10.002, uncertainty: 1e-5 })).toBe(true);
    expect(map.offset).toBe(10.002);
    expect(map.steps).toBe(1);
    // A noisy measurement (a wide bracket) does not move it for less than its own uncertainty.
    expect(map.adopt({ offset: 10.004, uncertainty: 0.003 })).toBe(false);
  });

  test("a sender's timestamp: plus liblsl's time correction, then onto the pipeline clock", () => {
    const map = new ClockMap();
    map.adopt({ offset: 5000 - 1.7e9, uncertainty: 0 }); // lsl = pipeline + offset
    // The sender's clock is 12.5 s behind ours: its 4987.5 is our LSL 5000, our pipeline 1.7e9.
    expect(senderToPipeline(4987.5, 12.5, map)).toBeCloseTo(1.7e9, 6);
    expect(senderToPipeline(4987.5 + 0.0005, 12.5, map)).toBeCloseTo(1.7e9 + 0.0005, 6);
  });

  test("latency mean, jitter (standard deviation) and extremes", () => {
    const s = new LatencyStats();
    expect(s.jitter).toBe(0);
    for (const v of [0.002, 0.004, 0.004, 0.004, 0.005, 0.005, 0.007, 0.009]) s.add(v);
    expect(s.mean).toBeCloseTo(0.005, 12);
    expect(s.jitter).toBeCloseTo(Math.sqrt(32e-6 / 7), 12);
    expect([s.min, s.max]).toEqual([0.002, 0.009]);
    s.reset();
    expect(s.n).toBe(0);
  });
});

describe("LSL helpers", () => {
  test("integer formats round half away from zero, clamp and count", () => {
    const v = Float64Array.from([1.5, -1.5, 2.4, NaN, 40000, -40000, 7]);
    expect(toIntegerFormat(v, 7, "int16")).toBe(3);
    expect(Array.from(v)).toEqual([2, -2, 2, 0, 32767, -32768, 7]);
    const w = Float64Array.from([3e9, -0.4]);
    expect(toIntegerFormat(w, 2, "int32")).toBe(1);
    expect(Array.from(w)).toEqual([2147483647, -0]);
    const f = Float64Array.from([1.25]);
    expect(toIntegerFormat(f, 1, "float32")).toBe(0);
    expect(f[0]).toBe(1.25);
  });

  test("the resolution predicate", () => {
    const p = { Name: "", Type: "", SourceId: "", Predicate: "" };
    expect(streamPredicate({ ...p, Name: "EMG" })).toBe("name='EMG'");
    expect(streamPredicate({ ...p, Name: "Bob's", Type: "EEG", SourceId: "x1" })).toBe(
      `name="Bob's" and type='EEG' and source_id='x1'`,
    );
    expect(streamPredicate({ ...p, Name: "A", Predicate: " hostname='lab' " })).toBe(
      "hostname='lab'",
    );
    expect(() => streamPredicate(p)).toThrow(/Name, Type, SourceId or a Predicate/);
    expect(() => xpathLiteral(`a'b"c`, "Name")).toThrow(/both ' and "/);
  });

  test("markers out and in", () => {
    expect(markerText(1, ["rest", "power"])).toBe("power");
    expect(markerText(2, ["rest", "power"])).toBe("2");
    expect(markerText(0.5, ["rest"])).toBe("0.5");
    expect(markerCode(2.5)).toBe(3);
    expect(markerCode(-1e12)).toBe(-2147483648);
    expect(markerValue("power", ["rest", "power"])).toBe(1);
    expect(markerValue(" 42 ", [])).toBe(42);
    expect(markerValue("oops", [])).toBeNaN();
    expect(markerValue("", [])).toBeNaN();
  });
});
