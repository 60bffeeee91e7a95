#!/usr/bin/env node
// The `mosaic` command. Runs the bundled CLI (build it with `npm run build`).
import { existsSync } from "node:fs";
import { fileURLToPath, pathToFileURL } from "node:url";

const cli = fileURLToPath(new URL("../dist/cli.mjs", import.meta.url));
if (!existsSync(cli)) {
  process.stderr.write(
    "mosaic: dist/cli.mjs is missing; run `npm run build` (or `npm test` / `npm start`) first\n",
  );
  process.exit(1);
}
await import(pathToFileURL(cli).href);
