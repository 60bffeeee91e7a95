/**
 * Issue 14, item 12 (recordings): a FilePlayer read `/dev/urandom` up to 1.1 GB, and held every
 * recording whole in memory. Now what is not a regular file is refused at once; a file bigger than
 * FILE_LIMITS.wholeBytes (32 MiB) is read in pieces as it plays, after its layout, first rows and
 * last line were checked at load, so memory stays small whatever its size; a bad line met while
 * playing stops it with an error naming the line; lines and columns are bounded.
 */
import { spawnSync } from "node:child_process";
import { existsSync, mkdtempSync, openSync, closeSync, writeSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { describe, expect, test } from "vitest";
import { FilePlayer } from "../../app/blocks/sources/file-player";
import { FILE_LIMITS } from "../../app/blocks/sources/delimited-text";
import { Frame } from "../../app/engine/frame";
import { BlockHarness } from "../../app/engine/testing";
import { nodeResources } from "../../app/host/resources";

const timer = { shape: { rows: 1, cols: 0 }, rate: 1000, isTimer: true };
const ticks = (from: number, n: number) =>
  Frame.from(
    { rows: 1, cols: 0 },
    Array.from({ length: n }, (_, i) => (from + i) / 1000),
    Array.from({ length: n }, () => []),
  );

/** A CSV of `rows` rows "time_s,a,b,c" with a = the row index; `bad` rows replaced by text. */
function writeCsv(file: string, rows: number, bad: Record<number, string> = {}): void {
  const fd = openSync(file, "w");
  writeSync(fd, "time_s,a,b,c\n");
  const pad = "0.123456789,-0.987654321"; // ~36 bytes a row
  let chunk = "";
  for (let i = 0; i < rows; i++) {
    chunk += bad[i] ?? `${(i / 1000).toFixed(3)},${i},${pad}\n`;
    if (chunk.length > 1 << 20) {
      writeSync(fd, chunk);
      chunk = "";
    }
  }
  writeSync(fd, chunk);
  closeSync(fd);
}

const dir = mkdtempSync(join(tmpdir(), "mosaic-rec-"));

describe("what is not a regular file is refused at once", () => {
  test.skipIf(!existsSync("/dev/urandom"))("/dev/urandom", async () => {
    const t0 = performance.now();
    await expect(
      BlockHarness.create(
        FilePlayer,
        { File: "/dev/urandom" },
        { resources: nodeResources(dir), inputs: [timer] },
      ),
    ).rejects.toThrow(
      "'/dev/urandom' is not a regular file (a device or a pipe): a FilePlayer plays recordings saved as files",
    );
    expect(performance.now() - t0).toBeLessThan(1000);
  });

  test("a pipe (opening it would wait for a writer)", async () => {
    const fifo = join(dir, "fifo.csv");
    if (spawnSync("mkfifo", [fifo]).status !== 0) return;
    await expect(
      BlockHarness.create(
        FilePlayer,
        { File: "fifo.csv" },
        { resources: nodeResources(dir), inputs: [timer] },
      ),
    ).rejects.toThrow(/fifo\.csv' is not a regular file/);
  });
});

describe("a big recording streams", () => {
  const big = join(dir, "big.csv");
  const rows = 1_100_000; // ~40 MB, above FILE_LIMITS.wholeBytes
  writeCsv(big, rows, { 1_050_000: "1050.000,oops,1,2\n" });

  test("loading reads the first rows only; playing keeps memory small; a bad line stops it, named", async () => {
    expect(rows * 36).toBeGreaterThan(FILE_LIMITS.wholeBytes);
    const heap0 = process.memoryUsage().heapUsed;
    const t0 = performance.now();
    const h = await BlockHarness.create(
      FilePlayer,
      { File: "big.csv" },
      { resources: nodeResources(dir), inputs: [timer] },
    );
    expect(performance.now() - t0).toBeLessThan(1000);
    expect(process.memoryUsage().heapUsed - heap0).toBeLessThan(16 << 20);
    h.start();
    expect(h.text).toBe("row 0");
    let next = 0;
    let ok = true;
    for (let k = 0; k < 230 && !h.finished; k++) {
      h.push(ticks(k * 5000, 5000));
      const out = h.output();
      for (const v of out.v) if (v[0] !== next++) ok = false;
      h.clear();
    }
    expect(ok).toBe(true);
    expect(next).toBe(1_050_000);
    expect(h.finished).toBe(true);
    expect(h.errors).toEqual([
      'stopped playing: line 1050002 of \'big.csv\': field 2 (column "a") is "oops", which is not a number',
    ]);
    expect(h.text).toMatch(/^stopped at row 1050000: line 1050002/);
    // The rows held at any time are a few chunks' worth, not the file.
    expect(process.memoryUsage().heapUsed - heap0).toBeLessThan(64 << 20);
    h.instance.dispose?.();
  });

  test("original timing and Loop: the last line is read at load, the next pass follows the last row", async () => {
    const saved = { ...FILE_LIMITS };
    Object.assign(FILE_LIMITS, { wholeBytes: 4096, chunkBytes: 512, firstRows: 20 });
    try {
      const small = join(dir, "loop.csv");
      writeCsv(small, 200); // ~12 KB: streamed with the lowered limit
      const h = await BlockHarness.create(
        FilePlayer,
        { File: "loop.csv", Loop: true },
        { resources: nodeResources(dir), now: 100 },
      );
      expect(h.desiredRate).toBeCloseTo(1000, 6);
      h.start();
      for (let i = 0; i < 450; i++) h.fireOneShot();
      const v = h.output().v.map((x) => x[0]);
      expect(v.slice(0, 3)).toEqual([0, 1, 2]);
      expect(v.slice(198, 203)).toEqual([198, 199, 0, 1, 2]);
      expect(v.length).toBe(450);
      // Pass 2 starts one median interval (1 ms) after the last row (0.199 s).
      expect(h.output().t[200]).toBeCloseTo(100.2, 9);
      expect(h.text).toMatch(/^row \d+ \/ 200 \(loop \d\)$/); // the total, known after a pass
    } finally {
      Object.assign(FILE_LIMITS, saved);
    }
  });

  test("a line longer than FILE_LIMITS.lineChars (a binary file) is refused when it loads", async () => {
    const saved = { ...FILE_LIMITS };
    Object.assign(FILE_LIMITS, { wholeBytes: 1024, lineChars: 4096 });
    try {
      const bin = join(dir, "bin.csv");
      const fd = openSync(bin, "w");
      writeSync(fd, "time_s,a\n0,1\n" + "x".repeat(10_000));
      closeSync(fd);
      await expect(
        BlockHarness.create(
          FilePlayer,
          { File: "bin.csv" },
          { resources: nodeResources(dir), inputs: [timer] },
        ),
      ).rejects.toThrow(
        "line 3 of 'bin.csv' is longer than 4096 characters: is it a text recording?",
      );
    } finally {
      Object.assign(FILE_LIMITS, saved);
    }
  });

  test("more columns than FILE_LIMITS.columns are refused", async () => {
    const wide = join(dir, "wide.csv");
    const fd = openSync(wide, "w");
    writeSync(fd, Array.from({ length: FILE_LIMITS.columns + 1 }, () => "1").join(",") + "\n");
    closeSync(fd);
    await expect(
      BlockHarness.create(
        FilePlayer,
        { File: "wide.csv" },
        { resources: nodeResources(dir), inputs: [timer] },
      ),
    ).rejects.toThrow(
      `line 1 of 'wide.csv' has ${FILE_LIMITS.columns + 1} fields; a recording may have at most ${FILE_LIMITS.columns} columns`,
    );
  });
});
