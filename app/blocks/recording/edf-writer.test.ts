import { describe, expect, test } from "vitest";
import { chooseRecordDuration, durationText, rateFraction } from "./edf-duration";
import { parseEdfHeader, parseTals } from "./edf-reader";
import {
  buildEdfHeader,
  edfNumber,
  formatOnset,
  headerDate,
  recordsField,
  RECORDS_OFFSET,
  writeTal,
  type EdfHeaderSpec,
} from "./edf-writer";

const text = (b: Uint8Array, from: number, width: number) =>
  String.fromCharCode(...b.subarray(from, from + width));

const spec = (format: "edf" | "bdf"): EdfHeaderSpec => ({
  format,
  patient: "X X X X",
  start: Date.UTC(2026, 10, 24, 9, 5, 7) / 1000,
  recording: "X X MOSAIC",
  recordDuration: "0.027",
  records: 0,
  signals: [
    {
      label: "Emg 1",
      transducer: "",
      dimension: "uV",
      physicalMin: -500,
      physicalMax: 500.123456789,
      digitalMin: -32768,
      digitalMax: 32767,
      prefiltering: "",
      samples: 52,
    },
    {
      label: "EDF Annotations",
      transducer: "",
      dimension: "",
      physicalMin: -1,
      physicalMax: 1,
      digitalMin: -32768,
      digitalMax: 32767,
      prefiltering: "",
      samples: 18,
    },
  ],
});

describe("EDF+ header (edf.html: field widths, ASCII, left-justified, space-padded)", () => {
  test("the general header's fields sit at the spec's byte offsets", () => {
    const h = buildEdfHeader(spec("edf"));
    expect(h.length).toBe(256 * 3);
    expect([...h].every((b) => b >= 32 && b <= 126)).toBe(true);
    expect(text(h, 0, 8)).toBe("0       ");
    expect(text(h, 8, 80)).toBe("X X X X".padEnd(80));
    expect(text(h, 88, 80)).toBe("Startdate 24-NOV-2026 X X MOSAIC".padEnd(80));
    expect(text(h, 168, 8)).toBe("24.11.26");
    expect(text(h, 176, 8)).toBe("09.05.07");
    expect(text(h, 184, 8)).toBe("768     ");
    expect(text(h, 192, 44)).toBe("EDF+C".padEnd(44));
    expect(text(h, 236, 8)).toBe("0       ");
    expect(text(h, 244, 8)).toBe("0.027   ");
    expect(text(h, 252, 4)).toBe("2   ");
  });

  test("signal fields are grouped per field, ns at a time (16, 80, 8×6, 80, 8, 32 bytes)", () => {
    const h = buildEdfHeader(spec("edf"));
    const ns = 2;
    let at = 256;
    const next = (w: number) => {
      const out = [text(h, at, w), text(h, at + w, w)];
      at += w * ns;
      return out;
    };
    expect(next(16)).toEqual(["Emg 1".padEnd(16), "EDF Annotations "]);
    expect(next(80)).toEqual([" ".repeat(80), " ".repeat(80)]);
    expect(next(8)).toEqual(["uV      ", "        "]);
    expect(next(8)).toEqual(["-500    ", "-1      "]);
    // 500.123456789 does not fit 8 characters: rounded up (a maximum keeps covering the range).
    expect(next(8)).toEqual(["500.1235", "1       "]);
    expect(next(8)).toEqual(["-32768  ", "-32768  "]);
    expect(next(8)).toEqual(["32767   ", "32767   "]);
    expect(next(80)).toEqual([" ".repeat(80), " ".repeat(80)]);
    expect(next(8)).toEqual(["52      ", "18      "]);
    expect(next(32)).toEqual([" ".repeat(32), " ".repeat(32)]);
    expect(at).toBe(768);
  });

  test("BDF+: version byte 255 then BIOSEMI, BDF+C, 24-bit digital range", () => {
    const s = spec("bdf");
    s.signals = s.signals.map((x) => ({ ...x, digitalMin: -8388608, digitalMax: 8388607 }));
    s.signals[1]!.label = "BDF Annotations";
    const h = buildEdfHeader(s);
    expect(h[0]).toBe(255);
    expect(text(h, 1, 7)).toBe("BIOSEMI");
    expect(text(h, 192, 44)).toBe("BDF+C".padEnd(44));
    const back = parseEdfHeader(h);
    expect(back.format).toBe("bdf");
    expect(back.bytesPerSample).toBe(3);
    expect(back.signals[0]!.digitalMin).toBe(-8388608);
    expect(back.signals[1]!.annotations).toBe(true);
    expect(back.recordBytes).toBe((52 + 18) * 3);
  });

  test("the reader gives back what was written; the record count is rewritten in place", () => {
    const h = buildEdfHeader(spec("edf"));
    h.set(recordsField(1234), RECORDS_OFFSET);
    const back = parseEdfHeader(h);
    expect(back.records).toBe(1234);
    expect(back.recordDuration).toBe(0.027);
    expect(back.start).toBe(Date.UTC(2026, 10, 24, 9, 5, 7) / 1000);
    expect(back.signals.map((s) => s.label)).toEqual(["Emg 1", "EDF Annotations"]);
    expect(back.signals[0]!.physicalMax).toBe(500.1235);
  });

  test("text is printable ASCII; a field too long is refused with its name", () => {
    const s = spec("edf");
    s.patient = "Jörg\tX X X";
    const h = buildEdfHeader(s);
    expect(text(h, 8, 10)).toBe("J_rg_X X X");
    s.signals[0]!.label = "a label of more than 16";
    expect(() => buildEdfHeader(s)).toThrow(/label of 'a label of more than 16'.*holds 16/);
  });

  test("numbers: exact when they fit, rounded outward otherwise; never an exponent", () => {
    expect(edfNumber(-32768, 8)).toBe("-32768");
    expect(edfNumber(0.0005, 8)).toBe("0.0005");
    expect(edfNumber(1e-7, 8, "up")).toBe("0.000001");
    expect(edfNumber(-1e-7, 8, "down")).toBe("-0.00001");
    expect(edfNumber(12345678.9, 8, "up")).toBe("12345679");
    expect(() => edfNumber(123456789, 8)).toThrow(/123456789 does not fit in 8 characters/);
    expect(edfNumber(-3.14159265, 8, "down")).toBe("-3.1416");
    expect(edfNumber(3.14159265, 8, "up")).toBe("3.141593");
    expect(headerDate(0)).toEqual({ date: "01.01.70", time: "00.00.00", startdate: "01-JAN-1970" });
  });
});

describe("TALs (edfplus.html 2.2.2: +onset[\\x15duration]\\x14text\\x14\\x00)", () => {
  test("time-keeping and marker TALs byte for byte", () => {
    const b = new Uint8Array(64);
    let p = writeTal(b, 0, 64, 250_000, "");
    expect(text(b, 0, p)).toBe("+0.25\x14\x14\x00");
    const q = writeTal(b, p, 64, 12_345_678, "Trigger.label=2");
    expect(text(b, p, q - p)).toBe("+12.345678\x14Trigger.label=2\x14\x00");
    p = q;
    expect(writeTal(b, p, 64, 1e6, "x".repeat(40))).toBe(-1);
    expect(parseTals(b)).toEqual([
      { onset: 0.25, duration: null, text: "" },
      { onset: 12.345678, duration: null, text: "Trigger.label=2" },
    ]);
    expect(formatOnset(0)).toBe("+0");
    expect(formatOnset(-1_500_000)).toBe("-1.5");
    expect(formatOnset(3_000_001)).toBe("+3.000001");
  });

  test("a TAL with a duration and two texts", () => {
    const b = new TextEncoder().encode("+1.5\x152\x14a\x14b\x14\x00\x00\x00");
    expect(parseTals(b)).toEqual([
      { onset: 1.5, duration: 2, text: "a" },
      { onset: 1.5, duration: 2, text: "b" },
    ]);
  });
});

describe("record duration: a whole number of samples of every rate", () => {
  test("rates are read as the device's fractions", () => {
    expect(rateFraction(1925.926)).toEqual({ p: 52000, q: 27 });
    expect(rateFraction(26 / 0.0135)).toEqual({ p: 52000, q: 27 });
    expect(rateFraction(148.148)).toEqual({ p: 4000, q: 27 });
    expect(rateFraction(2048)).toEqual({ p: 2048, q: 1 });
    expect(rateFraction(0.3)).toEqual({ p: 3, q: 10 });
  });

  const pick = (rates: number[], channels: number, fixed?: number) =>
    chooseRecordDuration(
      rates.map((rate, i) => ({ rate, bytesPerSample: channels * 2, name: `in${i}` })),
      fixed === undefined ? {} : { fixed },
    );

  test("Trigno 1925.926 Hz: multiples of 0.00675 s (13 samples); 0.027 s gives 52", () => {
    expect(pick([1925.926], 1)).toEqual({ us: 499_500, text: "0.4995", samples: [962] });
    expect(pick([1925.926], 1, 0.027)).toEqual({ us: 27_000, text: "0.027", samples: [52] });
    // 32 channels: the record stays within 61 440 bytes.
    expect(pick([1925.926], 32).samples[0]! * 64).toBeLessThanOrEqual(61440);
  });

  test("2000 Hz with 1925.926 Hz: multiples of 0.0135 s (27 and 26 samples)", () => {
    const d = pick([2000, 1925.926], 1);
    expect(d.us % 13_500).toBe(0);
    expect(d.samples).toEqual([(2000 * d.us) / 1e6, (52 * d.us) / 27_000]);
    expect(pick([2000], 1).text).toBe("0.5");
    expect(pick([2048], 1).text).toBe("0.5");
    expect(pick([200, 148.148], 1).text).toBe("0.405");
  });

  test("no duration up to 60 s: a clear error naming the inputs", () => {
    expect(() => pick([Math.PI], 1)).toThrow(/no record duration of at most 60 s.*in0 3.14159/);
    expect(() => pick([2000, 1925.926], 1, 0.5)).toThrow(
      /in1 at 1925.926 Hz gives 962.963 samples per 0.5 s record.*multiple of 0.0135 s/,
    );
  });

  test("duration texts are exact and at most 8 characters", () => {
    expect(durationText(27_000)).toBe("0.027");
    expect(durationText(15_625)).toBe("0.015625");
    expect(durationText(60_000_000)).toBe("60");
    expect(durationText(12_345_678)).toBeNull();
  });
});
