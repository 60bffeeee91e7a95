import { describe, expect, test } from "vitest";
import { parseDocument } from "yaml";
import { formatDiagnostic } from "../diagnostics";
import { Collector } from "./collector";
import { lineCounterOf } from "./parse";
import { checkPaths, logFilesOf, normalizeLogPath } from "./paths";
import type { BlockSpec } from "./spec";

const block = (name: string, path: string | undefined, outputs = ["out"]): BlockSpec =>
  ({ name, path, outputs, pos: { line: 1, col: 1 } }) as unknown as BlockSpec;

function check(blocks: BlockSpec[], source = "") {
  const c = new Collector("p.yaml", lineCounterOf(source));
  checkPaths(c, blocks, source ? parseDocument(source) : undefined);
  return c.list.map(formatDiagnostic);
}

describe("log paths stage", () => {
  test("normalises the folder part as written", () => {
    expect(normalizeLogPath("./a//b/../c.txt")).toBe("a/c.txt");
    expect(normalizeLogPath("a\\b\\c.txt")).toBe("a/b/c.txt");
    expect(normalizeLogPath("/x/../../y.txt")).toBe("/y.txt");
    expect(normalizeLogPath("../up/z.txt")).toBe("../up/z.txt");
  });

  test("the files a block writes: one per output, a file Path gets .<port> for named ports", () => {
    expect(logFilesOf(block("A", "logs/"))).toEqual([{ port: "out", file: "logs/A.txt" }]);
    expect(logFilesOf(block("A", "f.csv", ["a", "b"]))).toEqual([
      { port: "a", file: "f.csv" },
      { port: "b", file: "f.b.csv" },
    ]);
    expect(logFilesOf(block("A", undefined))).toEqual([]);
    expect(logFilesOf(block("S", "logs/", []))).toEqual([]);
  });

  test("different files pass; one Path folder for several blocks is fine", () => {
    expect(check([block("A", "logs/"), block("B", "logs/"), block("C", "logs/c.txt")])).toEqual([]);
  });

  test("two blocks on one file: an error at the second one's Path naming both", () => {
    const src = "A: { Type: T, Path: logs/B.txt }\nB: { Type: T, Path: ./logs }\n";
    expect(check([block("A", "logs/B.txt"), block("B", "./logs")], src)).toEqual([
      "p.yaml:2:21: error: block 'B': its log 'logs/B.txt' is also written by block 'A' (Path at 1:21); two writers on one file tear and lose lines (expected a Path of its own for 'B' or 'A' (another folder or file name))",
    ]);
  });

  test("names that differ only in case: a warning", () => {
    expect(check([block("A", "r/emg.txt"), block("B", "r/EMG.txt")])).toEqual([
      "p.yaml:1:1: warning: block 'B': its log 'r/EMG.txt' and block 'A''s 'r/emg.txt' differ only in case: one file on Windows and macOS, where they would tear each other's lines",
    ]);
  });
});
