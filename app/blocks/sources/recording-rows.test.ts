import { describe, expect, test } from "vitest";
import type { FileReadHandle } from "../../engine";
import { recordingKind, recordingRows } from "./recording-rows";

describe("recording rows", () => {
  test("recordingKind by extension", () => {
    expect(recordingKind("a/b.XDF")).toBe("xdf");
    expect(recordingKind("x.edf")).toBe("edf");
    expect(recordingKind("x.bdf")).toBe("edf");
    expect(recordingKind("x.csv")).toBeUndefined();
  });

  test("a file over the limit is refused before it is read", () => {
    const h: FileReadHandle = {
      path: "/big.xdf",
      size: 2 ** 40,
      read: () => {
        throw new Error("read");
      },
      close() {},
    };
    expect(() => recordingRows(h, "xdf", { file: "big.xdf" })).toThrow(
      /a FilePlayer reads XDF and EDF recordings whole, at most 536870912/,
    );
  });
});
