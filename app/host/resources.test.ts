import { mkdtempSync, readdirSync, readFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { expect, test } from "vitest";
import { nodeResources } from "./resources";

test("overlapping writes to one file leave exactly the last text, and no temporary files", async () => {
  const dir = mkdtempSync(join(tmpdir(), "mosaic-res-"));
  const r = nodeResources(dir);
  const texts = Array.from({ length: 40 }, (_, i) =>
    JSON.stringify({ i, pad: "x".repeat((40 - i) * 500) }),
  );
  await Promise.all(texts.map((t) => r.writeText("sub/model.json", t)));
  expect(readFileSync(join(dir, "sub/model.json"), "utf8")).toBe(texts.at(-1));
  expect(readdirSync(join(dir, "sub"))).toEqual(["model.json"]);
});

test("write errors name the file", async () => {
  const dir = mkdtempSync(join(tmpdir(), "mosaic-res-"));
  const r = nodeResources(dir);
  await r.writeText("plain.txt", "a file, not a folder");
  await expect(r.writeText("plain.txt/x.txt", "a")).rejects.toThrow(/plain\.txt\/x\.txt/);
});
