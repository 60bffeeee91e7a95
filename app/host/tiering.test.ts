import { execFileSync } from "node:child_process";
import { afterEach, describe, expect, it, vi } from "vitest";

const setFlagsFromString = vi.fn();
vi.mock("node:v8", () => ({ setFlagsFromString }));

afterEach(() => {
  setFlagsFromString.mockClear();
  vi.resetModules();
});

describe("V8 tiering for the engine", () => {
  it("sets each flag once, however often it is called", async () => {
    const { tuneTiering, TIERING_FLAGS } = await import("./tiering");
    tuneTiering();
    tuneTiering();
    expect(setFlagsFromString.mock.calls).toEqual(TIERING_FLAGS.map((f) => [f]));
  });

  it("keeps V8's own thresholds when MOSAIC_V8_TIERING=v8", async () => {
    const { tuneTiering, TIERING_ENV } = await import("./tiering");
    tuneTiering({ [TIERING_ENV]: "v8" });
    tuneTiering();
    expect(setFlagsFromString).not.toHaveBeenCalled();
  });

  it("lowers V8's thresholds rather than raising them", async () => {
    const { TIERING_FLAGS } = await import("./tiering");
    const defaults = execFileSync(process.execPath, ["--v8-options"], { encoding: "utf8" });
    for (const flag of TIERING_FLAGS) {
      const [name, value] = flag.split("=");
      // V8 lists each flag as "  --name (help)\n        type: int  default: --name=N".
      const listed = new RegExp(
        `\\n  ${name} \\([^\\n]*\\n\\s+type: int\\s+default: ${name}=(\\d+)`,
      );
      const found = listed.exec(defaults);
      expect(found, `${name} is not a flag of this Node's V8`).not.toBeNull();
      expect(Number(value)).toBeLessThan(Number(found![1]));
    }
  });
});
