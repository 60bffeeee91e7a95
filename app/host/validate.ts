/** Full validation of a pipeline file without running it (used by `mosaic validate`). */
import { readFileSync } from "node:fs";
import { dirname, resolve } from "node:path";
import { catalog } from "../blocks/catalog";
import { VirtualClock } from "../engine/clock";
import type { Diagnostic } from "../engine/diagnostics";
import { dspReady, initDsp } from "../engine/dsp";
import { loadPipeline } from "../engine/pipeline/loader";
import { withSimulatedDevices, type SimulateOptions } from "../engine/pipeline/simulate";
import { Runtime } from "../engine/runtime/runtime";
import { defaultWasmPath } from "./host";
import { nodeResources } from "./resources";

/** Loads the DSP core into this thread (once). */
export function loadDspFromDisk(path = defaultWasmPath()): void {
  if (!dspReady()) initDsp(readFileSync(path));
}

/** Parse, validate, then instantiate every block (shapes, files it reads) and dispose it again. */
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
  const loaded = withSimulatedDevices(
    loadPipeline(source, file, catalog),
    catalog,
    simulateDevices,
  );
  if (!loaded.spec) return loaded.diagnostics;
  loadDspFromDisk();
  const created = await Runtime.create({
    spec: loaded.spec,
    catalog,
    clock: new VirtualClock(0),
    virtual: true,
    resources: nodeResources(dirname(resolve(file))),
    ignorePlacement: true,
  });
  created.runtime?.dispose();
  return [...loaded.diagnostics, ...created.diagnostics];
}
