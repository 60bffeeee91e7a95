// Builds the browser build into dist/web/: the React UI (app/web/main.tsx), the engine worker
// (app/web/engine.worker.ts), the WASM core and the example pipelines with their data, so that
// any static file server can host it (with COOP/COEP headers for the precise timing).
import { build } from "esbuild";
import {
  copyFileSync,
  cpSync,
  existsSync,
  mkdirSync,
  readdirSync,
  readFileSync,
  rmSync,
  writeFileSync,
} from "node:fs";
import { dirname, join, relative } from "node:path";
import { fileURLToPath } from "node:url";

const root = join(dirname(fileURLToPath(import.meta.url)), "..");
const out = join(root, "dist/web");

if (!existsSync(join(root, "app/web/main.tsx"))) {
  console.log("build-web: app/web/main.tsx does not exist yet; nothing to build");
  process.exit(0);
}
rmSync(out, { recursive: true, force: true });
mkdirSync(out, { recursive: true });

const common = {
  absWorkingDir: root,
  bundle: true,
  platform: "browser",
  target: ["chrome110", "firefox115", "safari16"],
  format: "esm",
  sourcemap: "linked",
  minify: process.env.MOSAIC_WEB_DEBUG ? false : true,
  logLevel: "warning",
  define: { "process.env.NODE_ENV": '"production"' },
};
await build({
  ...common,
  entryPoints: { app: "app/web/main.tsx" },
  outdir: out,
  jsx: "automatic",
  loader: { ".css": "css" },
});
await build({
  ...common,
  entryPoints: { "engine.worker": "app/web/engine.worker.ts" },
  outdir: out,
});

copyFileSync(join(root, "app/web/index.html"), join(out, "index.html"));
const wasm = join(root, "core-wasm/pkg/mosaic_core_bg.wasm");
if (!existsSync(wasm))
  throw new Error("core-wasm/pkg/mosaic_core_bg.wasm is missing: run npm run build:wasm");
copyFileSync(wasm, join(out, "mosaic_core_bg.wasm"));

// Pipelines (and the data and schema they refer to), with an index for the pipeline picker.
const pipelines = join(root, "pipelines");
cpSync(pipelines, join(out, "pipelines"), { recursive: true });
const list = [];
const walk = (dir) => {
  for (const e of readdirSync(dir, { withFileTypes: true })) {
    const p = join(dir, e.name);
    if (e.isDirectory()) walk(p);
    else if (e.name.endsWith(".yaml")) {
      const text = readFileSync(p, "utf8");
      const comment = text
        .split("\n")
        .filter((l) => l.startsWith("#") && !l.includes("yaml-language-server"))
        .map((l) => l.replace(/^#\s?/, ""))
        .find((l) => l.trim() !== "");
      list.push({ file: relative(root, p).split("\\").join("/"), title: comment ?? e.name });
    }
  }
};
walk(pipelines);
list.sort((a, b) =>
  a.file === "pipelines/demo.yaml"
    ? -1
    : b.file === "pipelines/demo.yaml"
      ? 1
      : a.file.localeCompare(b.file),
);
writeFileSync(join(out, "pipelines/index.json"), JSON.stringify(list, null, 2) + "\n");
console.log(`build-web: wrote ${relative(root, out)} (${list.length} pipelines)`);
