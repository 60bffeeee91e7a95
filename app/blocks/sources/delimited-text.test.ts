import { describe, expect, test } from "vitest";
import {
  DelimitedStream,
  FILE_LIMITS,
  lastRowTime,
  parseDelimited,
  type ByteSource,
  type ParseOptions,
} from "./delimited-text";

const options = (o: Partial<ParseOptions> = {}): ParseOptions => ({
  file: "f.csv",
  header: "auto",
  delimiter: "auto",
  columns: undefined,
  timeColumn: undefined,
  ...o,
});

/** Bytes of `text` read in pieces. */
function bytes(text: string): ByteSource & { size: number } {
  const b = new TextEncoder().encode(text);
  return {
    size: b.length,
    read(into, position) {
      const n = Math.max(0, Math.min(into.length, b.length - position));
      into.set(b.subarray(position, position + n));
      return n;
    },
  };
}

/** Runs `fn` with FILE_LIMITS changed. */
function withLimits(l: Partial<typeof FILE_LIMITS>, fn: () => void): void {
  const saved = { ...FILE_LIMITS };
  Object.assign(FILE_LIMITS, l);
  try {
    fn();
  } finally {
    Object.assign(FILE_LIMITS, saved);
  }
}

/** Every row of a stream (values of the first column), releasing as it goes. */
function drain(s: DelimitedStream): number[] {
  const out: number[] = [];
  const v = new Float64Array(s.layout.columns.length);
  for (let r = 0; s.fill(r + 1) > r; r++) {
    s.copy(r, v, 0);
    out.push(v[0]!);
    s.release(r);
  }
  return out;
}

describe("DelimitedStream", () => {
  test("the same rows as parseDelimited, across chunk ends, CRLF, comments and multi-byte text", () => {
    let text = "time_s;é — name\r\n# a comment\r\n";
    for (let i = 0; i < 500; i++) text += `${i / 100};${i * 2}\r\n${i % 50 === 0 ? "\r\n" : ""}`;
    withLimits({ chunkBytes: 7 }, () => {
      const s = new DelimitedStream(bytes(text), options());
      expect(s.layout.names).toEqual(["time_s", "é — name"]);
      const whole = parseDelimited(text, options());
      const got = drain(s);
      expect(got).toEqual(Array.from(whole.values));
      expect(s.ended).toBe(true);
      expect(s.known).toBe(500);
      expect(s.time(499)).toBe(4.99);
      expect(s.line(499)).toBe(whole.lines[499]);
    });
  });

  test("released rows are dropped: the buffer stays small; rewind starts the next pass", () => {
    let text = "1,2\n"; // no header: the first line is a row
    for (let i = 1; i < 10_000; i++) text += `${i + 1},${i}\n`;
    const s = new DelimitedStream(bytes(text), options());
    expect(drain(s).slice(0, 3)).toEqual([1, 2, 3]);
    expect((s as unknown as { cap: number }).cap).toBeLessThanOrEqual(512);
    s.rewind();
    expect(drain(s).length).toBe(10_000);
  });

  test("a bad line ends the rows there, named; the rows before stay readable", () => {
    const s = new DelimitedStream(bytes("t,x\n0,1\n1,2\n2,x\n3,4\n"), options());
    expect(s.fill(10)).toBe(2);
    expect(s.error?.message).toBe(
      'line 4 of \'f.csv\': field 2 (column "x") is "x", which is not a number',
    );
  });

  test("the last row's time, read from the file's end", () => {
    const text = "t,x\n0,1\n0.5,2\n1.25,3\n\n# end\n";
    const src = bytes(text);
    const s = new DelimitedStream(src, options());
    expect(lastRowTime(src, src.size, s.layout, options())).toBe(1.25);
  });

  test("an empty file, and a line longer than lineChars", () => {
    expect(() => new DelimitedStream(bytes("\n# x\n"), options())).toThrow(
      "file 'f.csv' is empty (no data lines)",
    );
    withLimits({ lineChars: 100, chunkBytes: 16 }, () => {
      expect(() => new DelimitedStream(bytes("a".repeat(1000)), options())).toThrow(
        "line 1 of 'f.csv' is longer than 100 characters: is it a text recording?",
      );
    });
  });
});
