import { describe, expect, test } from "vitest";
import { normalizePath, resolveInFolder, OPEN_ITS_FOLDER } from "./protocol-folder";
import { parseUiMessage } from "./protocol";

const folder = {
  "session/examples/replay.yaml": "blob:a",
  "session/data/emg.csv": "blob:b",
  "session/examples/model.json": "blob:c",
};

describe("reading a block's file next to a pipeline opened from this computer", () => {
  test("paths are normalised, and leaving the top is refused", () => {
    expect(normalizePath("a/b/../c/./d")).toBe("a/c/d");
    expect(normalizePath("a\\b\\c")).toBe("a/b/c");
    expect(normalizePath("a/../..")).toBeUndefined();
  });

  test("a relative path is found against the pipeline's place in the folder", () => {
    expect(resolveInFolder(folder, "session/examples/replay.yaml", "../data/emg.csv")).toEqual({
      ok: true,
      path: "session/data/emg.csv",
      url: "blob:b",
    });
    expect(resolveInFolder(folder, "session/examples/replay.yaml", "model.json")).toMatchObject({
      ok: true,
      url: "blob:c",
    });
  });

  test("a file not in the folder, outside it, or absolute is one clear message", () => {
    const missing = resolveInFolder(folder, "session/examples/replay.yaml", "../data/x.csv");
    expect(missing).toEqual({
      ok: false,
      path: "session/data/x.csv",
      message: "not in the opened folder (no file session/data/x.csv)",
    });
    const outside = resolveInFolder(folder, "session/examples/replay.yaml", "../../up.csv");
    expect(outside.ok).toBe(false);
    expect(!outside.ok && outside.message).toContain("outside the opened folder 'session'");
    const absolute = resolveInFolder(folder, "session/examples/replay.yaml", "/home/me/emg.csv");
    expect(!absolute.ok && absolute.message).toContain("an absolute path");
  });

  test("a file picked alone (no folder) asks for its folder; a URL is read as it is", () => {
    const alone = resolveInFolder({}, "replay.yaml", "../data/emg.csv");
    expect(!alone.ok && alone.message).toContain("which folder replay.yaml is in");
    expect(!alone.ok && alone.message).toContain(OPEN_ITS_FOLDER);
    expect(resolveInFolder({}, "replay.yaml", "https://example.org/emg.csv")).toMatchObject({
      ok: true,
      url: "https://example.org/emg.csv",
    });
  });

  test("load and validate carry the folder through the protocol", () => {
    const m = parseUiMessage({ type: "load", id: 1, file: "r.yaml", source: "", folder });
    expect(m.ok && m.msg.type === "load" && m.msg.folder).toEqual(folder);
    const v = parseUiMessage({ type: "validate", id: 2, file: "r.yaml", source: "", folder: {} });
    expect(v.ok && v.msg.type === "validate" && v.msg.folder).toEqual({});
    const bad = parseUiMessage({ type: "load", id: 3, file: "r.yaml", source: "", folder: [1] });
    expect(bad.ok).toBe(false);
  });
});
