/**
 * The DLR ADC/BT simulator's pure parts: the frame bytes, the value function's range and
 * determinism, and `mosaic simulate dlr-adcbt`'s options. The simulator on a pty against the
 * block is tests/integration/dlr-adcbt.test.ts.
 */
import { describe, expect, test } from "vitest";
import {
  dlrAdcBtFrame,
  dlrAdcBtRaw,
  dlrAdcBtSimulatorOptions,
  dlrAdcBtVolts,
  startDlrAdcBtSimulator,
} from "./dlr-adcbt-simulator";

describe("frames and values", () => {
  test("a frame: AA 7A, length, 0, big-endian values, 0 0, FF FF", () => {
    expect([...dlrAdcBtFrame([0x0123, 4095])]).toEqual([
      0xaa, 0x7a, 12, 0, 0x01, 0x23, 0x0f, 0xff, 0, 0, 0xff, 0xff,
    ]);
    expect(dlrAdcBtFrame(new Array<number>(123).fill(0)).length).toBe(254);
  });

  test("values are 12-bit, deterministic, seeded, and differ between channels and frames", () => {
    const seen = new Set<string>();
    for (let k = 0; k < 2000; k++) {
      const row = [0, 1, 2, 3].map((c) => dlrAdcBtRaw(7, c, k));
      for (const r of row) {
        expect(Number.isInteger(r) && r >= 0 && r <= 4095).toBe(true);
      }
      seen.add(row.join());
    }
    // Every frame of 4 channels is told apart from the others (the tests find k from the values).
    expect(seen.size).toBe(2000);
    expect(dlrAdcBtRaw(7, 2, 123)).toBe(dlrAdcBtRaw(7, 2, 123));
    expect(dlrAdcBtRaw(7, 2, 123)).not.toBe(dlrAdcBtRaw(8, 2, 123));
    expect(dlrAdcBtVolts(7, 2, 123)).toBe((5 * dlrAdcBtRaw(7, 2, 123)) / 4000);
  });
});

describe("mosaic simulate dlr-adcbt's options", () => {
  test("checked, with what is wrong", () => {
    expect(dlrAdcBtSimulatorOptions({ port: "/tmp/b", rate: "250", channels: "8" })).toEqual({
      path: "/tmp/b",
      rate: 250,
      channels: 8,
    });
    expect(dlrAdcBtSimulatorOptions({ port: "/tmp/b", seed: "3", faults: "50" })).toEqual({
      path: "/tmp/b",
      seed: 3,
      faults: { every: 50 },
    });
    expect(() => dlrAdcBtSimulatorOptions({})).toThrow(/^--port PATH is required: .*socat pty/);
    expect(() => dlrAdcBtSimulatorOptions({ port: "/b", channels: "2.5" })).toThrow(
      "--channels must be a whole number, not '2.5'",
    );
    expect(() => dlrAdcBtSimulatorOptions({ port: "/b", channels: "124" })).toThrow(
      "channels must be 1…123 (a frame's length is one byte), not 124",
    );
    expect(() => dlrAdcBtSimulatorOptions({ port: "/b", rate: "0" })).toThrow(
      "rate must be in (0, 5000] Hz, not 0",
    );
    expect(() => dlrAdcBtSimulatorOptions({ port: "/b", faults: "0" })).toThrow(
      "faults.every must be a whole number of frames ≥ 1, not 0",
    );
  });

  test("a device that is not there: the error names it", async () => {
    await expect(startDlrAdcBtSimulator({ path: "/nonexistent/board" })).rejects.toThrow(
      /^cannot open \/nonexistent\/board: /,
    );
  });
});
