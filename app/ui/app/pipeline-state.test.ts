import { describe, expect, test } from "vitest";
import type { Diagnostic } from "../../engine/diagnostics";
import type { GraphInfo } from "../../engine/protocol";
import { afterLoad, keepsRunning, type PipelineState } from "./pipeline-state";

const graph = (file: string): GraphInfo => ({ file, blocks: [] });
const error: Diagnostic = {
  severity: "error",
  code: "unknown-type",
  message: "unknown block type 'EmgSimulatr'",
  file: "broken.yaml",
  line: 3,
  col: 14,
};

/** The demo loaded and running, as the hook holds it. */
const DEMO: PipelineState = {
  index: [],
  selected: "pipelines/demo.yaml",
  file: "pipelines/demo.yaml",
  source: "demo text",
  graph: graph("pipelines/demo.yaml"),
  generation: 3,
  loading: true,
  diagnostics: [],
  error: undefined,
  simulateDevices: true,
  rejected: undefined,
};

describe("afterLoad: what the page shows after a load", () => {
  test("a file that fails while the demo is kept: the demo stays, named, the failure beside it", () => {
    const failed = { ok: false, message: "the pipeline has errors", diagnostics: [error] };
    const s = afterLoad({ ...DEMO, selected: "broken.yaml" }, "broken.yaml", "x", failed, true);
    expect(keepsRunning(DEMO, failed, true)).toBe(true);
    expect(s.file).toBe("pipelines/demo.yaml");
    expect(s.selected).toBe("pipelines/demo.yaml");
    expect(s.graph).toBe(DEMO.graph);
    expect(s.source).toBe("demo text");
    expect(s.generation).toBe(3);
    expect(s.loading).toBe(false);
    expect(s.rejected).toEqual({ file: "broken.yaml", diagnostics: [error], error: undefined });
  });

  test("a failure the engine did not survive (empty), or with nothing shown: the failure alone", () => {
    const failed = { ok: false, message: "the pipeline has errors", diagnostics: [error] };
    for (const s of [
      afterLoad(DEMO, "broken.yaml", "x", failed, false),
      afterLoad({ ...DEMO, graph: undefined }, "broken.yaml", "x", failed, true),
    ]) {
      expect(s.file).toBe("broken.yaml");
      expect(s.graph).toBeUndefined();
      expect(s.diagnostics).toEqual([error]);
      expect(s.rejected).toBeUndefined();
    }
  });

  test("a load that works names the new pipeline everywhere (an untitled one too)", () => {
    const ok = { ok: true, diagnostics: [], graph: graph("pipelines/untitled.yaml") };
    const before = {
      ...DEMO,
      rejected: { file: "b.yaml", diagnostics: [error], error: undefined },
    };
    const s = afterLoad(before, "pipelines/untitled.yaml", "new text", ok, true);
    expect(s.file).toBe("pipelines/untitled.yaml");
    expect(s.selected).toBe("pipelines/untitled.yaml");
    expect(s.graph?.file).toBe("pipelines/untitled.yaml");
    expect(s.source).toBe("new text");
    expect(s.generation).toBe(4);
    expect(s.rejected).toBeUndefined();
  });
});
