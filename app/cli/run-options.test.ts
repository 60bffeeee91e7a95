import { describe, expect, it } from "vitest";
import { DEFAULT_TELEMETRY_HZ } from "../host/worker-protocol";
import { hostOptions, parseRunOptions, type RunOptions } from "./run-options";

function parsed(args: string[]): RunOptions {
  const o = parseRunOptions(args);
  if (typeof o === "string") throw new Error(o);
  return o;
}

describe("mosaic run options: telemetry rate and batching", () => {
  it("telemetry at the default rate (the UI's, 20 Hz) unless --telemetry-hz says otherwise", () => {
    expect(DEFAULT_TELEMETRY_HZ).toBe(20);
    expect(parsed(["p.yaml"]).telemetryHz).toBe(20);
    expect(hostOptions(parsed(["p.yaml"])).telemetryHz).toBe(20);
    expect(parsed(["p.yaml", "--telemetry-hz", "2"]).telemetryHz).toBe(2);
  });

  it("refuses a rate outside (0, 100] and a batching interval outside [0, 1000], naming the value", () => {
    expect(parseRunOptions(["p.yaml", "--telemetry-hz", "0"])).toBe(
      "mosaic run: --telemetry-hz must be between 0 and 100, not '0'",
    );
    expect(parseRunOptions(["p.yaml", "--telemetry-hz", "fast"])).toBe(
      "mosaic run: --telemetry-hz must be between 0 and 100, not 'fast'",
    );
    expect(parseRunOptions(["p.yaml", "--batching-ms", "2000"])).toBe(
      "mosaic run: --batching-ms must be between 0 and 1000 milliseconds, not '2000'",
    );
  });

  it("the batching interval reaches the host in seconds; absent, the pipeline's own decides", () => {
    expect(hostOptions(parsed(["p.yaml", "--batching-ms", "2"])).batchingS).toBe(0.002);
    expect(hostOptions(parsed(["p.yaml"])).batchingS).toBeUndefined();
  });
});
