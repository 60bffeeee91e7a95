// Bundles the Node entry points into dist/ with esbuild.
//  - product (CLI, engine worker): pure-JS packages bundled in (one file to compile, less memory);
//    code that only some commands need (validation) is split into lazily loaded chunks.
//  - tools (docs generator): packages stay in node_modules.
import { build } from "esbuild";
import { copyFileSync, existsSync, mkdirSync, rmSync } from "node:fs";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";

const root = join(dirname(fileURLToPath(import.meta.url)), "..");
const present = (entries) =>
  Object.fromEntries(Object.entries(entries).filter(([, src]) => existsSync(join(root, src))));

const common = {
  absWorkingDir: root,
  bundle: true,
  platform: "node",
  target: "node20",
  format: "esm",
  outExtension: { ".js": ".mjs" },
  sourcemap: "linked",
  logLevel: "warning",
  // No comments nor indentation in what V8 keeps as source (one copy per thread that loads a
  // chunk; a comment's "µ" or "—" made a whole chunk a two-byte string): ~2 MiB less per worker.
  // Names stay, and the linked source maps give file:line.
  minifyWhitespace: true,
  banner: {
    js: "import { createRequire as __cr } from 'node:module'; const require = __cr(import.meta.url);",
  },
};

rmSync(join(root, "dist/chunks"), { recursive: true, force: true });
await build({
  ...common,
  entryPoints: present({
    cli: "app/cli/main.ts",
    "engine.worker": "app/host/engine.worker.ts",
    "session.worker": "app/host/session.worker.ts",
  }),
  outdir: "dist",
  splitting: true,
  chunkNames: "chunks/[name]-[hash]",
  // Native modules cannot be bundled; esbuild (loading users' block modules) runs its binary.
  external: ["serialport", "@serialport/*", "@abandonware/noble", "electron", "koffi", "esbuild"],
});
// The block SDK (package.json exports "./sdk") for users' own scripts and tests; MOSAIC itself
// hands a loaded block module its own SDK object (app/host/user-blocks.ts).
await build({
  ...common,
  entryPoints: present({ sdk: "app/engine/sdk.ts" }),
  outdir: "dist",
  banner: {},
});
await build({
  ...common,
  entryPoints: present({ "tools/gen-docs": "tools/gen-docs.ts" }),
  outdir: "dist",
  packages: "external",
});

const wasm = join(root, "core-wasm/pkg/mosaic_core_bg.wasm");
if (existsSync(wasm)) {
  mkdirSync(join(root, "dist"), { recursive: true });
  copyFileSync(wasm, join(root, "dist/mosaic_core_bg.wasm"));
}
