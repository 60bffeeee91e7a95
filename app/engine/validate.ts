/**
 * The one full check of a pipeline's text without running it: the loader's diagnostics (every
 * stage, all at once), then, when it loads, every block instantiated on a virtual clock (shapes,
 * the files it reads) and disposed again. `mosaic validate` (app/host/validate.ts) and the
 * engine session's `validate` request (the UI editor) both call it, so they say the same.
 * The DSP core must be loaded.
 */
import type { Resources } from "./block";
import type { Catalog } from "./catalog";
import { VirtualClock } from "./clock";
import type { Diagnostic } from "./diagnostics";
import { loadPipeline, type LoadResult } from "./pipeline/loader";
import { withSimulatedDevices, type SimulateOptions } from "./pipeline/simulate";
import { Runtime } from "./runtime/runtime";

export interface ValidateOptions {
  /** Files the blocks read, relative to the pipeline file's folder. */
  resources: Resources;
  /** Check the pipeline as it would run with simulated devices (absent: as written). */
  simulateDevices?: SimulateOptions;
  /** Parses elsewhere (the host's loader thread); `loadPipeline` here when absent. */
  parse?(source: string, file: string): Promise<LoadResult>;
}

/** Every problem of the pipeline `source` (named `file` in the diagnostics), in file order per stage. */
export async function validatePipeline(
  source: string,
  file: string,
  catalog: Catalog,
  options: ValidateOptions,
): Promise<Diagnostic[]> {
  const parsed = options.parse
    ? await options.parse(source, file)
    : loadPipeline(source, file, catalog);
  const loaded = withSimulatedDevices(parsed, catalog, options.simulateDevices);
  if (!loaded.spec) return loaded.diagnostics;
  const created = await Runtime.create({
    spec: loaded.spec,
    catalog,
    clock: new VirtualClock(0),
    virtual: true,
    resources: options.resources,
    ignorePlacement: true,
  });
  created.runtime?.dispose();
  return [...loaded.diagnostics, ...created.diagnostics];
}
