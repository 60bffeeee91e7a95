import { mkdtempSync, readFileSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { describe, expect, test } from "vitest";
import { openFileWrite } from "./file-write";

const dir = () => mkdtempSync(join(tmpdir(), "mosaic-write-"));

describe("openFileWrite", () => {
  test("appends, rewrites in place, creates folders; bytes reach the file at once", () => {
    const f = join(dir(), "a", "b", "rec.bin");
    const h = openFileWrite(f);
    h.write(Uint8Array.of(1, 2, 3));
    h.write(Uint8Array.of(4, 5));
    h.writeAt(Uint8Array.of(9, 9), 1);
    expect(h.size).toBe(5);
    // Before close: another reader (as after a kill -9) already sees everything.
    expect([...readFileSync(f)]).toEqual([1, 9, 9, 4, 5]);
    h.sync();
    h.close();
    h.close();
    expect(() => h.write(Uint8Array.of(0))).toThrow(/is closed/);
  });

  test("never replaces a file unless asked; past-the-end rewrites are refused", () => {
    const f = join(dir(), "rec.bin");
    writeFileSync(f, "old");
    expect(() => openFileWrite(f)).toThrow(`${f} exists already: not overwritten`);
    const h = openFileWrite(f, { overwrite: true });
    h.write(Uint8Array.of(7));
    expect(() => h.writeAt(Uint8Array.of(1, 2), 0)).toThrow(/past the end/);
    h.close();
    expect([...readFileSync(f)]).toEqual([7]);
  });

  test("a folder or a forbidden place is named in the error", () => {
    const d = dir();
    expect(() => openFileWrite(d, { overwrite: true })).toThrow(`${d} is a folder, not a file`);
  });
});
