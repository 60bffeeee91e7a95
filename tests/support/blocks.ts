/** Small helpers for block tests: frames from plain arrays, one-block legacy conversion. */
import { expect } from "vitest";
import { catalog } from "../../app/blocks/catalog";
import {
  EMPTY_SHAPE,
  Frame,
  loadPipeline,
  matrixShape,
  vectorShape,
  type Diagnostic,
} from "../../app/engine";

/** A timer frame with these tick times. */
export const ticks = (...times: number[]): Frame =>
  Frame.from(
    EMPTY_SHAPE,
    times,
    times.map(() => []),
  );

/** A vector frame: one row of `values` per timestamp. */
export const vectors = (times: readonly number[], values: readonly (readonly number[])[]): Frame =>
  Frame.from(vectorShape(values[0]!.length), times, values);

/** A matrix frame: each event a list of rows. */
export const matrices = (
  times: readonly number[],
  values: readonly (readonly (readonly number[])[])[],
): Frame => {
  const rows = values[0]!.length;
  const cols = values[0]![0]!.length;
  return Frame.from(
    matrixShape(rows, cols),
    times,
    values.map((m) => m.flat()),
  );
};

export interface Converted {
  params: unknown;
  warnings: Diagnostic[];
  errors: Diagnostic[];
}

/** Loads `yaml` with the catalog and returns the params of `block` and the diagnostics. */
export function loadBlock(yaml: string, block: string): Converted {
  const r = loadPipeline(yaml, "test.yaml", catalog);
  const warnings = r.diagnostics.filter((d) => d.severity === "warning");
  const errors = r.diagnostics.filter((d) => d.severity === "error");
  const params = r.spec?.byName.get(block)?.params;
  return { params, warnings, errors };
}

/**
 * Converts a block's positional Params through the loader and checks there is exactly one
 * `legacy-converted` warning and no error; returns the validated params.
 */
export function convertLegacy(yaml: string, block: string): unknown {
  const r = loadBlock(yaml, block);
  expect(r.errors).toEqual([]);
  expect(r.warnings).toHaveLength(1);
  expect(r.warnings[0]!.code).toBe("legacy-converted");
  expect(r.warnings[0]!.block).toBe(block);
  return r.params;
}
