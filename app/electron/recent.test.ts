import { existsSync, mkdtempSync, readdirSync, readFileSync, rmSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join, resolve } from "node:path";
import { afterEach, beforeEach, describe, expect, test } from "vitest";
import {
  addRecent,
  loadRecent,
  RECENT_LIMIT,
  RecentFiles,
  removeRecent,
  sanitizeRecent,
  saveRecent,
} from "./recent";

const abs = (name: string): string => resolve("/pipelines", name);

describe("recent list operations", () => {
  test("add puts the file first, removes its older entry, caps at 10", () => {
    let list: string[] = [];
    for (let i = 0; i < 12; i++) list = addRecent(list, abs(`p${i}.yaml`));
    expect(list).toHaveLength(RECENT_LIMIT);
    expect(list[0]).toBe(abs("p11.yaml"));
    expect(list.at(-1)).toBe(abs("p2.yaml"));
    list = addRecent(list, abs("p5.yaml"));
    expect(list[0]).toBe(abs("p5.yaml"));
    expect(list.filter((f) => f === abs("p5.yaml"))).toHaveLength(1);
    expect(list).toHaveLength(RECENT_LIMIT);
  });

  test("dedupes normalized paths, and by case when asked", () => {
    const a = addRecent([abs("x/../demo.yaml")], abs("demo.yaml"));
    expect(a).toEqual([abs("demo.yaml")]);
    expect(addRecent([abs("Demo.yaml")], abs("demo.yaml"))).toHaveLength(2);
    expect(addRecent([abs("Demo.yaml")], abs("demo.yaml"), { caseInsensitive: true })).toEqual([
      abs("demo.yaml"),
    ]);
    expect(addRecent([], abs("a.yaml"), { limit: 0 })).toEqual([]);
  });

  test("remove", () => {
    expect(removeRecent([abs("a.yaml"), abs("b.yaml")], abs("a.yaml"))).toEqual([abs("b.yaml")]);
  });

  test("sanitize keeps absolute string paths only, deduped and capped", () => {
    const files = [abs("a.yaml"), "relative.yaml", 3, null, "", abs("a.yaml"), "x\0y", abs("b")];
    expect(sanitizeRecent(files)).toEqual([abs("a.yaml"), abs("b")]);
    expect(sanitizeRecent({ version: 1, files })).toEqual([abs("a.yaml"), abs("b")]);
    expect(sanitizeRecent({ files: "nope" })).toEqual([]);
    expect(sanitizeRecent(42)).toEqual([]);
    const many = Array.from({ length: 30 }, (_, i) => abs(`f${i}.yaml`));
    expect(sanitizeRecent(many)).toHaveLength(RECENT_LIMIT);
  });
});

describe("persistence", () => {
  let dir: string;
  beforeEach(() => {
    dir = mkdtempSync(join(tmpdir(), "mosaic-recent-"));
  });
  afterEach(() => rmSync(dir, { recursive: true, force: true }));

  test("save then load round-trips; no temporary file is left", () => {
    const store = join(dir, "sub", "recent.json");
    saveRecent(store, [abs("a.yaml"), abs("b.yaml")]);
    expect(JSON.parse(readFileSync(store, "utf8"))).toEqual({
      version: 1,
      files: [abs("a.yaml"), abs("b.yaml")],
    });
    expect(loadRecent(store)).toEqual([abs("a.yaml"), abs("b.yaml")]);
    expect(readdirSync(join(dir, "sub"))).toEqual(["recent.json"]);
  });

  test("a missing, corrupt or foreign file loads as an empty list", () => {
    expect(loadRecent(join(dir, "missing.json"))).toEqual([]);
    const store = join(dir, "recent.json");
    for (const text of ["{not json", "", "null", '"a string"', "[1,2,3]", '{"files":{}}']) {
      writeFileSync(store, text);
      expect(loadRecent(store), text).toEqual([]);
    }
    // A folder where the file should be.
    expect(loadRecent(dir)).toEqual([]);
  });

  test("RecentFiles adds, persists, removes and clears; a bad file does not stop it", () => {
    const store = join(dir, "recent.json");
    writeFileSync(store, "garbage");
    const r = new RecentFiles(store);
    expect(r.files).toEqual([]);
    r.add(abs("a.yaml"));
    r.add(abs("b.yaml"));
    r.add(abs("a.yaml"));
    expect(r.files).toEqual([abs("a.yaml"), abs("b.yaml")]);
    expect(new RecentFiles(store).files).toEqual([abs("a.yaml"), abs("b.yaml")]);
    r.remove(abs("a.yaml"));
    expect(new RecentFiles(store).files).toEqual([abs("b.yaml")]);
    r.clear();
    expect(new RecentFiles(store).files).toEqual([]);
  });

  test("a save that fails is reported, and the list still changes in memory", () => {
    const errors: string[] = [];
    // The store's folder is a file: mkdir fails.
    const blocker = join(dir, "blocker");
    writeFileSync(blocker, "");
    const r = new RecentFiles(join(blocker, "recent.json"), { onError: (m) => errors.push(m) });
    r.add(abs("a.yaml"));
    expect(r.files).toEqual([abs("a.yaml")]);
    expect(errors[0]).toMatch(/cannot save the recent files list/);
    expect(existsSync(join(blocker, "recent.json"))).toBe(false);
  });
});
