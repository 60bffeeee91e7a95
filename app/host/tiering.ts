/**
 * V8's tiering thresholds for a soft-real-time engine.
 *
 * V8 runs a function in its interpreter or baseline tier until the function has executed about
 * 66 KB of bytecode (`--interrupt-budget`), and waits another 500 calls after any inline cache
 * changes (`--minimum-invocations-after-ic-update`) before optimizing it; a WebAssembly function
 * stays in Liftoff, the baseline compiler, until it has run ~1.8 MB of code
 * (`--wasm-tiering-budget`). Those thresholds suit a web page's hot loops; a block's `process`
 * called 25 or 200 times a second on a few events reaches them after minutes, or never when a
 * cue change updates a cache now and then. Profiled on the bench's Myo pipeline after 15 s, most
 * block code still ran in the baseline tier, every property access through a generic inline-cache
 * stub; at 90–120 s it still did. With the thresholds below the same code is optimized within
 * the first seconds: the Myo pipeline used 2.40 / 2.44 % of a core against 2.93 / 3.10 % (two
 * pairs side by side; README.md, "Performance").
 *
 * The flags are process-wide and must be set before the engine's workers compile their code: the
 * Node host and the session hub call `tuneTiering` before they start a worker. Browsers do not let
 * a page set them (the web build runs with the browser's own thresholds). `MOSAIC_V8_TIERING=v8`
 * in the environment keeps V8's own thresholds (the bench's tiering sweep compares the two).
 */
import { setFlagsFromString } from "node:v8";

/** The V8 flags `tuneTiering` sets (see the module comment for why each). */
export const TIERING_FLAGS = [
  "--interrupt-budget=8000",
  "--minimum-invocations-after-ic-update=20",
  "--wasm-tiering-budget=100000",
] as const;

/** The environment variable that, set to "v8", keeps V8's own thresholds. */
export const TIERING_ENV = "MOSAIC_V8_TIERING";

let tuned = false;

/**
 * Lowers V8's tier-up thresholds for this process (once; later calls do nothing), unless the
 * environment asks for V8's own (`TIERING_ENV`).
 */
export function tuneTiering(env: NodeJS.ProcessEnv = process.env): void {
  if (tuned) return;
  tuned = true;
  if (env[TIERING_ENV] === "v8") return;
  for (const flag of TIERING_FLAGS) setFlagsFromString(flag);
}
