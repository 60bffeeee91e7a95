import { BlockConfigError } from "../../engine";
import { dspReady } from "../../engine/dsp";

/** Blocks built on the wasm kernels call this first, for a clear message when it is not loaded. */
export function requireDsp(type: string): void {
  if (!dspReady()) {
    throw new BlockConfigError(
      `${type} needs the DSP module, which this runtime has not loaded (initDsp was not called ` +
        "with core-wasm/pkg/mosaic_core_bg.wasm; build it with `npm run build:wasm`)",
    );
  }
}
