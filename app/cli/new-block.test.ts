import { existsSync, mkdirSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { afterEach, describe, expect, it } from "vitest";
import {
  blockTypeName,
  cmdNewBlock,
  createRustBlock,
  nextSteps,
  rustTemplateDir,
} from "./new-block";

const made: string[] = [];
function temp(): string {
  const d = mkdtempSync(join(tmpdir(), "mosaic-new-block-"));
  made.push(d);
  return d;
}
afterEach(() => {
  for (const d of made.splice(0)) rmSync(d, { recursive: true, force: true });
});

describe("mosaic new-block --rust", () => {
  it("names the block type in PascalCase", () => {
    expect(blockTypeName("tkeo")).toBe("Tkeo");
    expect(blockTypeName("my-tkeo")).toBe("MyTkeo");
    expect(blockTypeName("emg_onset2")).toBe("EmgOnset2");
  });

  it("copies the template without build outputs and names the crate, the .wasm and the type", () => {
    const parent = temp();
    const r = createRustBlock("my-tkeo", parent);
    expect(r).toEqual({ dir: join(parent, "my-tkeo"), type: "MyTkeo", libName: "my_tkeo" });
    const read = (f: string) => readFileSync(join(r.dir, f), "utf8");
    expect(read("Cargo.toml")).toContain('name = "my-tkeo"');
    expect(read("block.ts")).toContain('const TYPE = "MyTkeo";');
    expect(read("block.ts")).toContain(
      'import wasm from "./target/wasm32-unknown-unknown/release/my_tkeo.wasm";',
    );
    expect(read("block.ts")).toContain('wasmName: "my_tkeo.wasm"');
    expect(read("tests/reference.rs")).toContain("use my_tkeo::abi::");
    expect(read("tests/reference.rs")).not.toContain("use tkeo::");
    for (const f of ["src/abi.rs", "src/tkeo.rs", "src/lib.rs", "tests/fixtures/tkeo.json"]) {
      expect(read(f)).toBe(readFileSync(join(rustTemplateDir(), f), "utf8"));
    }
    // The editor's type checker finds mosaic/sdk in this MOSAIC's sources.
    const tsconfig = JSON.parse(read("tsconfig.json")) as {
      compilerOptions: { paths: Record<string, string[]>; strict: boolean };
      include: string[];
    };
    const sdk = join(rustTemplateDir(), "..", "..", "app", "engine", "sdk.ts");
    expect(tsconfig.compilerOptions.paths["mosaic/sdk"]).toEqual([sdk]);
    expect(existsSync(sdk)).toBe(true);
    expect(tsconfig.compilerOptions.strict).toBe(true);
    expect(tsconfig.include).toEqual(["block.ts", "wasm.d.ts"]);
    expect(existsSync(join(r.dir, "target"))).toBe(false);
    expect(existsSync(join(r.dir, "Cargo.lock"))).toBe(false);
  });

  it("says what to run next, with paths as typed from where it was run", () => {
    const parent = temp();
    const r = createRustBlock("tkeo", parent);
    const here = nextSteps(r, parent);
    expect(here).toContain("cd tkeo && cargo build --release --target wasm32-unknown-unknown");
    expect(here).toContain("use it in a pipeline in ./ (Blocks: paths are relative");
    expect(here).toContain("Pipeline: { Blocks: [tkeo/block.ts] }");
    expect(here).toContain("Energy: { Type: Tkeo, Inputs: [YourSignal] }");
    expect(here).toContain("mosaic test-block tkeo/block.ts");
    // Run from elsewhere (`mosaic new-block --rust tkeo /tmp/x`): absolute paths, same Blocks line.
    const elsewhere = nextSteps(r, join(parent, "..", "somewhere-else"));
    expect(elsewhere).toContain(`cd ${r.dir} && cargo build`);
    expect(elsewhere).toContain(`use it in a pipeline in ${parent}/`);
    expect(elsewhere).toContain("Pipeline: { Blocks: [tkeo/block.ts] }");
    expect(elsewhere).toContain(`mosaic test-block ${r.dir}/block.ts`);
  });

  it("refuses a name that cannot name a crate and a folder that is not empty", () => {
    const parent = temp();
    expect(() => createRustBlock("My Block", parent)).toThrow(
      "'My Block' cannot name a crate: use lower case letters, digits, '-' and '_', starting with a letter",
    );
    mkdirSync(join(parent, "busy"));
    writeFileSync(join(parent, "busy", "keep.txt"), "mine");
    expect(() => createRustBlock("busy", parent)).toThrow(
      `${join(parent, "busy")} exists and is not empty`,
    );
    expect(readFileSync(join(parent, "busy", "keep.txt"), "utf8")).toBe("mine");
  });

  it("as a command: exit codes and messages", () => {
    const parent = temp();
    const out: string[] = [];
    const err: string[] = [];
    expect(
      cmdNewBlock(
        ["tkeo", parent],
        (s) => out.push(s),
        (s) => err.push(s),
      ),
    ).toBe(2);
    expect(err.pop()).toContain("only Rust blocks are made from a template (--rust NAME [DIR])");
    expect(
      cmdNewBlock(
        ["--rust"],
        (s) => out.push(s),
        (s) => err.push(s),
      ),
    ).toBe(2);
    expect(err.pop()).toBe("mosaic new-block: usage: mosaic new-block --rust NAME [DIR]");
    expect(
      cmdNewBlock(
        ["--rust", "tkeo", parent],
        (s) => out.push(s),
        (s) => err.push(s),
      ),
    ).toBe(0);
    expect(out.pop()).toContain("the Rust block Tkeo");
    expect(existsSync(join(parent, "tkeo", "block.ts"))).toBe(true);
    expect(
      cmdNewBlock(
        ["--rust", "tkeo", parent],
        (s) => out.push(s),
        (s) => err.push(s),
      ),
    ).toBe(1);
    expect(err.pop()).toMatch(/^mosaic new-block: .*tkeo exists and is not empty$/);
  });
});
