// Runs the UI benchmark (tests/bench/ui/ui-bench.ts) with plain node: bundles it and the harness
// page with esbuild into dist/bench-ui/, then runs it with the given options. Needs the browser
// build (node scripts/build-web.mjs). `npm run bench:ui -- --mode harness` etc.
import { build } from "esbuild";
import { existsSync, mkdirSync, writeFileSync } from "node:fs";
import { dirname, join } from "node:path";
import { fileURLToPath, pathToFileURL } from "node:url";

const root = join(dirname(fileURLToPath(import.meta.url)), "../../..");
const out = join(root, "dist/bench-ui");
mkdirSync(out, { recursive: true });

if (!existsSync(join(root, "dist/web/index.html"))) {
  console.error("ui-bench: dist/web is missing: run node scripts/build-web.mjs first");
  process.exit(1);
}

await build({
  absWorkingDir: root,
  entryPoints: { harness: "tests/bench/ui/harness.tsx" },
  outdir: out,
  bundle: true,
  platform: "browser",
  format: "esm",
  target: ["chrome110"],
  jsx: "automatic",
  loader: { ".css": "css" },
  minify: true,
  sourcemap: "linked",
  logLevel: "warning",
  define: { "process.env.NODE_ENV": '"production"' },
});
writeFileSync(
  join(out, "harness.html"),
  `<!doctype html>
<html lang="en">
  <head>
    <meta charset="utf-8" />
    <title>MOSAIC panels (bench harness)</title>
    <link rel="stylesheet" href="harness.css" />
  </head>
  <body>
    <div id="root"></div>
    <script type="module" src="harness.js"></script>
  </body>
</html>
`,
);
await build({
  absWorkingDir: root,
  entryPoints: { "ui-bench": "tests/bench/ui/ui-bench.ts" },
  outdir: out,
  outExtension: { ".js": ".mjs" },
  bundle: true,
  platform: "node",
  format: "esm",
  target: "node20",
  packages: "external",
  logLevel: "warning",
});
process.env.MOSAIC_ROOT ??= root;
await import(pathToFileURL(join(out, "ui-bench.mjs")).href);
