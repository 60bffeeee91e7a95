/** Entry point of the `mosaic` command (bundled to dist/cli.mjs). */
import { main } from "./commands";

main(process.argv.slice(2)).then(
  (code) => {
    process.exitCode = code;
  },
  (e: unknown) => {
    process.stderr.write(`mosaic: ${(e as Error).stack ?? String(e)}\n`);
    process.exitCode = 1;
  },
);
