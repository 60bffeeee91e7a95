// Bundles the desktop app's main process and preload (app/electron) into dist/electron/ as
// CommonJS for Electron: main.cjs (the host in-process: SessionHub, bridges) and preload.cjs
// (sandboxed: it may only require "electron", so everything else is bundled in). The engine
// session the main process starts is dist/session.worker.mjs from scripts/build-ts.mjs, and the
// UI is dist/web from scripts/build-web.mjs: run those first.
import { build } from "esbuild";
import { existsSync, rmSync } from "node:fs";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";

const root = join(dirname(fileURLToPath(import.meta.url)), "..");
const out = join(root, "dist/electron");

rmSync(out, { recursive: true, force: true });

const common = {
  absWorkingDir: root,
  bundle: true,
  format: "cjs",
  outExtension: { ".js": ".cjs" },
  outdir: out,
  sourcemap: "linked",
  logLevel: "warning",
  // Electron 45: Node 22, Chromium 140.
  target: "node22",
  // Native modules cannot be bundled; electron is provided by the runtime.
  external: ["electron", "serialport", "@serialport/*", "@abandonware/noble"],
};

await build({
  ...common,
  entryPoints: { main: "app/electron/main.ts" },
  platform: "node",
  // The host finds files next to its module with import.meta.url; in CommonJS that is this file.
  define: { "import.meta.url": "__mosaic_import_meta_url" },
  banner: { js: 'const __mosaic_import_meta_url = require("url").pathToFileURL(__filename).href;' },
});

await build({
  ...common,
  entryPoints: { preload: "app/electron/preload.ts" },
  // The sandboxed preload has no Node: only `require("electron")` and browser globals.
  platform: "browser",
  external: ["electron"],
});

for (const needed of [
  "dist/session.worker.mjs",
  "dist/mosaic_core_bg.wasm",
  "dist/web/index.html",
]) {
  if (!existsSync(join(root, needed))) {
    console.warn(`build-electron: ${needed} is missing: run build-ts.mjs and build-web.mjs too`);
  }
}
console.log("build-electron: wrote dist/electron/main.cjs and dist/electron/preload.cjs");
