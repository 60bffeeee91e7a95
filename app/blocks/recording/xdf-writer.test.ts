/**
 * The XDF writer, reader and repair against the specification
 * (https://github.com/sccn/xdf/wiki/Specifications, "Format specification of XDF 1.0"): the
 * variable-length integers, the chunk layout `[NumLengthBytes][Length][Tag][Content]`, the
 * Samples, ClockOffset and Boundary contents byte by byte, and a file cut at every byte of its
 * last chunk read and repaired.
 */
import { describe, expect, test } from "vitest";
import { XdfFileWriter } from "./xdf-file";
import { bytesSource, readXdf, xmlField } from "./xdf-reader";
import { planXdfRepair } from "./xdf-repair";
import { MemoryFile } from "./xdf-testing";
import {
  BOUNDARY_UUID,
  ByteBuffer,
  MarkerStream,
  NumericStream,
  putBoundary,
  putClockOffset,
  putVarLen,
  putXmlChunk,
  streamHeaderXml,
  varLenSize,
  type StreamInfo,
} from "./xdf-writer";

const le64 = (x: number): number[] => [...new Uint8Array(Float64Array.of(x).buffer)];
const le32f = (x: number): number[] => [...new Uint8Array(Float32Array.of(x).buffer)];
const varLen = (n: number): number[] => {
  const b = new ByteBuffer(16);
  b.length = putVarLen(b.view, 0, n);
  return [...b.used];
};

describe("XDF variable-length integers (spec: NumLengthBytes 1, 4 or 8, then the value LE)", () => {
  test("the smallest width that holds the value", () => {
    expect(varLen(0)).toEqual([1, 0]);
    expect(varLen(255)).toEqual([1, 255]);
    expect(varLen(256)).toEqual([4, 0, 1, 0, 0]);
    expect(varLen(0xffff_ffff)).toEqual([4, 255, 255, 255, 255]);
    expect(varLen(0x1_0000_0000)).toEqual([8, 0, 0, 0, 0, 1, 0, 0, 0]);
    expect(varLen(2 ** 40 + 5)).toEqual([8, 5, 0, 0, 0, 0, 1, 0, 0]);
    for (const n of [0, 255, 256, 0xffff_ffff, 0x1_0000_0000]) {
      expect(varLen(n)).toHaveLength(varLenSize(n));
    }
  });
  test("a length that is not a whole number of bytes is refused", () => {
    expect(() => varLen(-1)).toThrow(/whole number/);
    expect(() => varLen(1.5)).toThrow(/whole number/);
  });
});

describe("XDF chunks byte by byte", () => {
  test("ClockOffset: Length counts the tag, the StreamId and two float64", () => {
    const b = new ByteBuffer();
    putClockOffset(b, 7, 1234.5, -0.25);
    expect([...b.used]).toEqual([1, 22, 4, 0, 7, 0, 0, 0, ...le64(1234.5), ...le64(-0.25)]);
  });

  test("Boundary: tag 5 and the specification's UUID", () => {
    const b = new ByteBuffer();
    putBoundary(b);
    expect([...b.used]).toEqual([1, 18, 5, 0, ...BOUNDARY_UUID]);
    expect(Buffer.from(BOUNDARY_UUID).toString("hex")).toBe("43a546dccbf5410fb30ed5467383cbe4");
  });

  test("Samples: StreamId, NumSamples, then per sample TimeStampBytes 8, the stamp, the values", () => {
    const s = new NumericStream(3, 2, "float32");
    s.append(Float64Array.of(10, 10.5, 11), Float64Array.of(1, 2, 0.5, -0.25, 3, 4), 3, 2);
    const b = new ByteBuffer();
    s.takeChunk(b);
    const sample = (t: number, a: number, c: number) => [8, ...le64(t), ...le32f(a), ...le32f(c)];
    const content = [
      3,
      0,
      0,
      0,
      ...varLen(3),
      ...sample(10, 1, 2),
      ...sample(10.5, 0.5, -0.25),
      ...sample(11, 3, 4),
    ];
    expect([...b.used]).toEqual([1, 2 + content.length, 3, 0, ...content]);
    expect(s.written).toBe(3);
    expect(s.pending).toBe(0);
  });

  test("a chunk over 255 bytes takes a 4-byte Length; double64 values are 8 bytes", () => {
    const s = new NumericStream(1, 4, "double64");
    const n = 20;
    const t = Float64Array.from({ length: n }, (_, i) => i / 100);
    const v = Float64Array.from({ length: n * 4 }, (_, i) => Math.PI * i);
    s.append(t, v, n, 4);
    const b = new ByteBuffer();
    s.takeChunk(b);
    const length = 2 + 4 + 2 + n * (9 + 32);
    expect([...b.used.subarray(0, 7)]).toEqual([
      4,
      ...new Uint8Array(Uint32Array.of(length).buffer),
      3,
      0,
    ]);
    expect(b.length).toBe(5 + length);
  });

  test("strings: a variable-length byte count, then UTF-8", () => {
    const m = new MarkerStream(2);
    m.append(5, "go ✓");
    const b = new ByteBuffer();
    m.takeChunk(b);
    const utf = [...Buffer.from("go ✓", "utf8")];
    const content = [2, 0, 0, 0, 1, 1, 8, ...le64(5), 1, utf.length, ...utf];
    expect([...b.used]).toEqual([1, 2 + content.length, 3, 0, ...content]);
  });

  test("XML is escaped and control characters dropped", () => {
    const b = new ByteBuffer();
    const xml = streamHeaderXml(info({ name: 'a<b>&"c"\u0001' }));
    putXmlChunk(b, 2, 1, xml);
    expect(xml).toContain("<name>a&lt;b&gt;&amp;&quot;c&quot;</name>");
    expect(xmlField(xml, "name")).toBe('a<b>&"c"');
  });
});

function info(o: Partial<StreamInfo> = {}): StreamInfo {
  return {
    name: "Emg",
    type: "EMG",
    channelCount: 2,
    nominalRate: 100,
    format: "float32",
    sourceId: "MOSAIC/Rec/Emg",
    labels: ["a", "b"],
    unit: "mV",
    createdAt: 1,
    uid: "u",
    hostname: "",
    ...o,
  };
}

/** A file of a 2-channel stream (0.01 s apart, values exact in float32) and a marker stream. */
function recordFile(): { file: MemoryFile; w: XdfFileWriter } {
  const file = new MemoryFile();
  const w = new XdfFileWriter(
    file,
    [
      info(),
      info({
        name: "Cue",
        type: "Markers",
        channelCount: 1,
        nominalRate: 0,
        format: "string",
        labels: ["Cue"],
      }),
    ],
    100,
    "2026-01-01T00:00:00Z",
  );
  const num = w.streams[0] as NumericStream;
  const mark = w.streams[1] as MarkerStream;
  for (let k = 0; k < 30; k++) {
    const t = 100 + k * 0.01;
    num.append(Float64Array.of(t), Float64Array.of(k, -k / 4), 1, 2);
    if (k % 10 === 0) mark.append(t, `cue ${k}`);
    if (k % 7 === 6) w.flush(t);
  }
  return { file, w };
}

describe("XDF files: write, read, cut, repair", () => {
  test("a closed file reads back exactly, with headers, offsets, boundaries and footers", () => {
    const { file, w } = recordFile();
    w.flush(111); // past the 10-s boundary and the 5-s clock offset
    w.close(112);
    expect(file.closed).toBe(true);
    expect(file.syncs).toBe(1);
    const x = readXdf(bytesSource(file.bytes));
    expect(x.problem).toBe("");
    expect(xmlField(x.fileHeader, "version")).toBe("1.0");
    expect(x.boundaries).toBe(1);
    const [emg, cue] = x.streams;
    expect(emg!.header).toMatchObject({
      id: 1,
      name: "Emg",
      channelCount: 2,
      nominalRate: 100,
      format: "float32",
      labels: ["a", "b"],
    });
    expect([...emg!.t]).toEqual(Array.from({ length: 30 }, (_, k) => 100 + k * 0.01));
    expect([...emg!.values!]).toEqual(Array.from({ length: 30 }, (_, k) => [k, -k / 4]).flat());
    expect(cue!.strings).toEqual(["cue 0", "cue 10", "cue 20"]);
    expect(emg!.clockOffsets).toEqual([
      [100, 0],
      [111, 0],
      [112, 0],
    ]);
    expect(xmlField(emg!.footer!, "sample_count")).toBe("30");
    expect(Number(xmlField(emg!.footer!, "last_timestamp"))).toBe(100 + 29 * 0.01);
    expect(xmlField(cue!.footer!, "first_timestamp")).toBe("100");
    // A whole file needs no repair.
    expect(planXdfRepair(bytesSource(file.bytes))).toMatchObject({
      changed: false,
      keep: file.size,
    });
  });

  test("cut at every byte of its last write: whole chunks read, the repair restores the footers", () => {
    const { file, w } = recordFile();
    const before = file.size; // after the flush at k = 27
    w.flush(100.3);
    const whole = file.bytes;
    expect(whole.length).toBeGreaterThan(before);
    const complete = readXdf(bytesSource(whole));
    for (let cut = before; cut <= whole.length; cut++) {
      const bytes = whole.subarray(0, cut);
      // A reader stops at the torn chunk without throwing.
      expect(() => readXdf(bytesSource(bytes))).not.toThrow();
      const plan = planXdfRepair(bytesSource(bytes));
      const repaired = new Uint8Array(plan.keep + plan.append.length);
      repaired.set(bytes.subarray(0, plan.keep));
      repaired.set(plan.append, plan.keep);
      const r = readXdf(bytesSource(repaired));
      expect(r.problem).toBe("");
      for (const s of r.streams) {
        const n = s.t.length;
        expect(xmlField(s.footer!, "sample_count")).toBe(String(n));
        if (n > 0) {
          expect(Number(xmlField(s.footer!, "first_timestamp"))).toBe(s.t[0]);
          expect(Number(xmlField(s.footer!, "last_timestamp"))).toBe(s.t[n - 1]);
        }
      }
      // Nothing whole is lost: at least what was there before the last write.
      expect(r.streams[0]!.t.length).toBeGreaterThanOrEqual(28);
      if (cut === whole.length) {
        expect(r.streams[0]!.t.length).toBe(complete.streams[0]!.t.length);
        expect(plan.keep).toBe(whole.length);
      }
    }
  });

  test("other writers' forms: a sample without a timestamp follows the previous one by 1/srate; int16", () => {
    const b = new ByteBuffer();
    b.put(Uint8Array.of(0x58, 0x44, 0x46, 0x3a));
    putXmlChunk(
      b,
      2,
      9,
      streamHeaderXml(info({ channelCount: 1, nominalRate: 4, labels: ["x"] })).replace(
        "float32",
        "int16",
      ),
    );
    // Samples: 3 samples, the first stamped, the next two not (TimeStampBytes 0).
    const content = [9, 0, 0, 0, 1, 3, 8, ...le64(2), 0xfe, 0xff, 0, 5, 0, 0, 0x00, 0x80];
    b.put(Uint8Array.from([1, 2 + content.length, 3, 0, ...content]));
    const x = readXdf(bytesSource(b.used.slice()));
    expect(x.problem).toBe("");
    expect([...x.streams[0]!.t]).toEqual([2, 2.25, 2.5]);
    expect([...x.streams[0]!.values!]).toEqual([-2, 5, -32768]);
  });

  test("a damaged StreamHeader ends the readable part; the repair drops it", () => {
    const { file, w } = recordFile();
    w.close(101);
    const good = file.bytes;
    const b = new ByteBuffer();
    b.put(good);
    putXmlChunk(b, 2, 7, "<info><channel_count>x</channel_count></info>");
    const bytes = b.used.slice();
    expect(readXdf(bytesSource(bytes)).problem).toMatch(
      /damaged StreamHeader: stream 7: its header has no valid channel_count/,
    );
    const plan = planXdfRepair(bytesSource(bytes));
    expect(plan.keep).toBe(good.length);
    expect(plan.append.length).toBe(0);
    expect(plan.messages[0]).toMatch(
      /^dropped the last \d+ bytes: byte \d+: a damaged StreamHeader/,
    );
  });

  test("not an XDF file: a clear error", () => {
    expect(() => planXdfRepair(bytesSource(new TextEncoder().encode("EDF+ something")))).toThrow(
      /not an XDF file/,
    );
  });
});
