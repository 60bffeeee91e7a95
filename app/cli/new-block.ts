/**
 * `mosaic new-block --rust NAME [DIR]`: copies the Rust block template (templates/rust-block/) to
 * DIR/NAME, named after NAME (the crate, its `.wasm` file, the block type), and says how to build
 * it and use it in a pipeline (docs/writing-blocks.md, "Rust blocks").
 */
import { cpSync, existsSync, readdirSync, readFileSync, writeFileSync } from "node:fs";
import { basename, dirname, isAbsolute, join, relative, resolve, sep } from "node:path";
import { fileURLToPath } from "node:url";
import { parseArgs } from "node:util";

type Print = (s: string) => void;

export function newBlockHelp(): string {
  return `  mosaic new-block --rust NAME [DIR]
      Creates a block written in Rust in DIR/NAME (DIR: the current folder by default): a
      crate whose kernel (src/tkeo.rs, the Teager–Kaiser energy operator as an example) builds
      to a WebAssembly module, block.ts, the block MOSAIC loads (type name: NAME in
      PascalCase), and a tsconfig.json for editors (mosaic/sdk: this MOSAIC's SDK). NAME: lower case letters, digits, '-' and '_', starting with a letter.
      Prints the build command and how to use it in a pipeline (docs/writing-blocks.md).`;
}

/** What `createRustBlock` made. */
export interface NewRustBlock {
  /** The crate's folder. */
  dir: string;
  /** The block type pipelines use ("my-tkeo" → "MyTkeo"). */
  type: string;
  /** The crate's name with '-' as '_': the `.wasm` file's name. */
  libName: string;
}

const NAME_RE = /^[a-z][a-z0-9_-]*$/;

/** "my-tkeo" → "MyTkeo". */
export function blockTypeName(name: string): string {
  return name
    .split(/[-_]+/)
    .filter((part) => part.length > 0)
    .map((part) => part[0]!.toUpperCase() + part.slice(1))
    .join("");
}

/** templates/rust-block of this MOSAIC (from the sources or the bundle in dist/). */
export function rustTemplateDir(): string {
  let d = dirname(fileURLToPath(import.meta.url));
  for (let i = 0; i < 6; i++) {
    const t = join(d, "templates", "rust-block");
    if (existsSync(join(t, "Cargo.toml"))) return t;
    d = dirname(d);
  }
  throw new Error("the Rust block template (templates/rust-block) is missing from this MOSAIC");
}

/** The template's names that follow NAME, file by file (no-ops for NAME "tkeo"). */
function renames(name: string, type: string, libName: string) {
  return [
    { file: "Cargo.toml", from: 'name = "tkeo"', to: `name = "${name}"` },
    { file: "tests/reference.rs", from: "use tkeo::", to: `use ${libName}::` },
    { file: "block.ts", from: "/release/tkeo.wasm", to: `/release/${libName}.wasm` },
    { file: "block.ts", from: 'wasmName: "tkeo.wasm"', to: `wasmName: "${libName}.wasm"` },
    { file: "block.ts", from: 'const TYPE = "Tkeo";', to: `const TYPE = "${type}";` },
  ];
}

/** Copies the template to `parent/name` and names it; throws with the reason when it cannot. */
export function createRustBlock(
  name: string,
  parent: string,
  template = rustTemplateDir(),
): NewRustBlock {
  if (!NAME_RE.test(name)) {
    throw new Error(
      `'${name}' cannot name a crate: use lower case letters, digits, '-' and '_', starting with a letter`,
    );
  }
  const dir = resolve(parent, name);
  if (existsSync(dir) && readdirSync(dir).length > 0) {
    throw new Error(`${dir} exists and is not empty`);
  }
  const type = blockTypeName(name);
  const libName = name.replaceAll("-", "_");
  cpSync(template, dir, {
    recursive: true,
    filter: (src) => {
      const rel = relative(template, src);
      return rel !== "target" && !rel.startsWith(`target${sep}`) && rel !== "Cargo.lock";
    },
  });
  for (const r of renames(name, type, libName)) {
    const path = join(dir, r.file);
    const text = readFileSync(path, "utf8");
    if (!text.includes(r.from)) {
      throw new Error(`the template's ${r.file} has no '${r.from}' (templates/rust-block changed)`);
    }
    writeFileSync(path, text.replaceAll(r.from, r.to));
  }
  writeEditorConfig(dir, template);
  return { dir, type, libName };
}

/**
 * tsconfig.json for the user's editor and `npx tsc -p .`: `mosaic/sdk` is this MOSAIC's SDK
 * source (docs/writing-blocks.md, "Types in your editor"); MOSAIC itself needs no build step.
 */
function writeEditorConfig(dir: string, template: string): void {
  const sdk = join(dirname(dirname(template)), "app", "engine", "sdk.ts");
  if (!existsSync(sdk)) return;
  const config = {
    compilerOptions: {
      strict: true,
      target: "es2022",
      module: "esnext",
      moduleResolution: "bundler",
      noEmit: true,
      skipLibCheck: true,
      types: [],
      paths: { "mosaic/sdk": [sdk] },
    },
    include: ["block.ts", "wasm.d.ts"],
  };
  writeFileSync(join(dir, "tsconfig.json"), `${JSON.stringify(config, null, 2)}\n`);
}

/** `path` as the user may type it from `cwd`: relative below it, else absolute. */
function shownPath(path: string, cwd: string): string {
  const rel = relative(cwd, path);
  if (rel === "") return ".";
  return rel.startsWith("..") || isAbsolute(rel) ? path : rel;
}

/** The lines that tell the user what to do next (paths as typed from `cwd`). */
export function nextSteps(made: NewRustBlock, cwd: string): string {
  const crate = shownPath(made.dir, cwd).replaceAll("\\", "/");
  const parent = shownPath(dirname(made.dir), cwd).replaceAll("\\", "/");
  const name = basename(made.dir);
  return [
    `created ${crate}/: the Rust block ${made.type} (its kernel: src/tkeo.rs; its block: block.ts)`,
    "build it (and after every change to src/):",
    `  cd ${crate} && cargo build --release --target wasm32-unknown-unknown`,
    `use it in a pipeline in ${parent}/ (Blocks: paths are relative to the pipeline file):`,
    `  Pipeline: { Blocks: [${name}/block.ts] }`,
    `  Energy: { Type: ${made.type}, Inputs: [YourSignal] }`,
    "check it:",
    `  mosaic test-block ${crate}/block.ts`,
    "(docs/writing-blocks.md, 'Rust blocks'; needs: rustup target add wasm32-unknown-unknown)",
  ].join("\n");
}

export function cmdNewBlock(args: string[], out: Print, err: Print): number {
  const { values, positionals } = parseArgs({
    args,
    options: { rust: { type: "boolean" } },
    allowPositionals: true,
  });
  if (!values.rust) {
    err(
      "mosaic new-block: only Rust blocks are made from a template (--rust NAME [DIR]); a " +
        "TypeScript block is one file: see docs/writing-blocks.md",
    );
    return 2;
  }
  const [name, parent = ".", ...extra] = positionals;
  if (name === undefined || extra.length > 0) {
    err("mosaic new-block: usage: mosaic new-block --rust NAME [DIR]");
    return 2;
  }
  try {
    const made = createRustBlock(name, parent);
    out(nextSteps(made, process.cwd()));
    return 0;
  } catch (e) {
    err(`mosaic new-block: ${(e as Error).message}`);
    return 1;
  }
}
