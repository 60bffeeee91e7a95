/**
 * The Rust block template (templates/rust-block/) for tests: copy it to a folder, edit it, build
 * it with cargo for wasm32-unknown-unknown; and its NumPy fixture (tests/fixtures/tkeo.json).
 */
import { spawnSync } from "node:child_process";
import { cpSync, readFileSync, writeFileSync } from "node:fs";
import { join, relative, sep } from "node:path";
import { fileURLToPath } from "node:url";

export const TEMPLATE = fileURLToPath(new URL("../../templates/rust-block/", import.meta.url));

export interface TkeoFixture {
  frames: number;
  channels: number;
  input: number[];
  expected: number[];
  expected_rectified: number[];
}

export function tkeoFixture(): TkeoFixture {
  const path = join(TEMPLATE, "tests", "fixtures", "tkeo.json");
  return JSON.parse(readFileSync(path, "utf8")) as TkeoFixture;
}

/** A text replacement in one file of the copy; `from` must be there. */
export interface TemplateEdit {
  file: string;
  from: string;
  to: string;
}

/** Copies the template to `dir` (without build outputs), applies `edits`, builds it; returns the .wasm bytes. */
export function buildTemplate(dir: string, edits: readonly TemplateEdit[] = []): Uint8Array {
  cpSync(TEMPLATE, dir, {
    recursive: true,
    filter: (src) => {
      const rel = relative(TEMPLATE, src);
      return rel !== "target" && !rel.startsWith(`target${sep}`) && rel !== "Cargo.lock";
    },
  });
  for (const e of edits) {
    const path = join(dir, e.file);
    const text = readFileSync(path, "utf8");
    if (!text.includes(e.from)) throw new Error(`${e.file} has no '${e.from}'`);
    writeFileSync(path, text.replace(e.from, e.to));
  }
  const r = spawnSync(
    "cargo",
    ["build", "--release", "--target", "wasm32-unknown-unknown", "--quiet"],
    { cwd: dir, encoding: "utf8", timeout: 240_000 },
  );
  if (r.status !== 0) throw new Error(`cargo build failed in ${dir}:\n${r.stderr}`);
  return readFileSync(join(dir, "target", "wasm32-unknown-unknown", "release", "tkeo.wasm"));
}

/** The edit that makes a build speak ABI version `v`. */
export const abiVersionEdit = (v: number): TemplateEdit => ({
  file: "src/abi.rs",
  from: "ABI_VERSION: u32 = 1",
  to: `ABI_VERSION: u32 = ${v}`,
});
