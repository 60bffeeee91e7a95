/** Full validation of a pipeline file without running it (used by `mosaic validate`). */
import { readFileSync } from "node:fs";
import { dirname, resolve } from "node:path";
import { catalog } from "../blocks/catalog";
import type { Diagnostic } from "../engine/diagnostics";
import { dspReady, initDsp } from "../engine/dsp";
import type { SimulateOptions } from "../engine/pipeline/simulate";
import { pipelineCatalog } from "../engine/user-blocks";
import { validatePipeline } from "../engine/validate";
import { defaultWasmPath } from "./host";
import { nodeResources } from "./resources";
import { loadBlockModule } from "./user-blocks";

/** Loads the DSP core into this thread (once). */
export function loadDspFromDisk(path = defaultWasmPath()): void {
  if (!dspReady()) initDsp(readFileSync(path));
}

/** Reads the file and checks it as the engine does (app/engine/validate.ts). */
export async function validatePipelineFile(
  file: string,
  simulateDevices?: SimulateOptions,
): Promise<Diagnostic[]> {
  let source: string;
  try {
    source = readFileSync(file, "utf8");
  } catch (e) {
    const code = (e as NodeJS.ErrnoException).code;
    return [
      {
        severity: "error",
        code: "file",
        message: code === "ENOENT" ? "no such file" : `cannot read: ${(e as Error).message}`,
        file,
        line: 0,
        col: 0,
      },
    ];
  }
  loadDspFromDisk();
  const own = await pipelineCatalog(source, file, catalog, loadBlockModule);
  if (own.diagnostics.some((d) => d.severity === "error")) return own.diagnostics;
  return validatePipeline(source, file, own.catalog, {
    resources: nodeResources(dirname(resolve(file))),
    ...(simulateDevices ? { simulateDevices } : {}),
  });
}
