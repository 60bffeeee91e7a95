/**
 * Loads the DSP module for tests (Node): reads core-wasm/pkg/mosaic_core_bg.wasm from the repo
 * and calls `initDsp` once per test worker. Build it with `npm run build:wasm` if it is missing.
 */
import { readFileSync } from "node:fs";
import { dspReady, initDsp } from "../../app/engine/dsp";

const ROOT = new URL("../../", import.meta.url);
const WASM = new URL("core-wasm/pkg/mosaic_core_bg.wasm", ROOT);

export function initDspForTests(): void {
  if (dspReady()) return;
  let bytes: Buffer;
  try {
    bytes = readFileSync(WASM);
  } catch (e) {
    throw new Error(
      `cannot read ${WASM.pathname} (${e instanceof Error ? e.message : String(e)}); ` +
        "build the DSP module with `npm run build:wasm`",
    );
  }
  initDsp(bytes);
}
