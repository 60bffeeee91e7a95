// Bundles the Node entry points (CLI, engine worker, tools) into dist/ with esbuild.
// The engine and blocks are plain TypeScript modules bundled into each entry.
import { build } from "esbuild";
import { copyFileSync, existsSync, mkdirSync } from "node:fs";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";

const root = join(dirname(fileURLToPath(import.meta.url)), "..");

/** entry (repo-relative) → output (dist-relative, .mjs) */
export const entries = {
  "app/cli/main.ts": "cli.mjs",
  "app/host/engine.worker.ts": "engine.worker.mjs",
  "tools/gen-docs.ts": "tools/gen-docs.mjs",
};

const present = Object.entries(entries).filter(([src]) => existsSync(join(root, src)));
await build({
  absWorkingDir: root,
  entryPoints: Object.fromEntries(present.map(([src, out]) => [out.replace(/\.mjs$/, ""), src])),
  outdir: "dist",
  outExtension: { ".js": ".mjs" },
  bundle: true,
  platform: "node",
  target: "node20",
  format: "esm",
  sourcemap: "linked",
  logLevel: "warning",
  // Packages stay in node_modules (native modules cannot be bundled; keeps dist small).
  packages: "external",
  banner: {
    js: "import { createRequire as __cr } from 'node:module'; const require = __cr(import.meta.url);",
  },
});

const wasm = join(root, "core-wasm/pkg/mosaic_core_bg.wasm");
if (existsSync(wasm)) {
  mkdirSync(join(root, "dist"), { recursive: true });
  copyFileSync(wasm, join(root, "dist/mosaic_core_bg.wasm"));
}
