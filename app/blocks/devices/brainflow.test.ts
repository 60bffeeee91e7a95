/**
 * The BrainFlow block's TypeScript side without a sidecar: its params, the channel names, which
 * param a load error points at, the status words, and the block where there is no Python (the
 * browser build). tests/integration/brainflow.test.ts runs it with real sidecars and boards.
 */
import { describe, expect, test } from "vitest";
import { BlockHarness } from "../../engine/testing";
import { BrainFlow } from "./brainflow";
import { BoardState, paramOfError, stateText, type BoardCounts } from "./brainflow-link";
import { channelNames } from "./brainflow-run";

const counts = (state: BoardState, failures = 0): BoardCounts => ({
  state,
  lost: 0,
  reconnects: 0,
  failures,
  total: 0,
});

describe("BrainFlow (no sidecar)", () => {
  test("params: a board by name or number, EXG channels at 50 Hz polls by default", () => {
    const p = BrainFlow.params.parse({ Board: "CYTON_BOARD", SerialPort: "/dev/ttyUSB0" });
    expect(p).toMatchObject({ Library: "auto", Channels: ["exg"], PollRate: 50, Silence: 3 });
    expect(BrainFlow.params.parse({ Board: -1 }).Board).toBe(-1);
    expect(BrainFlow.params.safeParse({ Board: "x", Channels: ["exg", "exg"] }).success).toBe(
      false,
    );
    expect(BrainFlow.params.safeParse({ Board: "x", Channels: ["eda"] }).success).toBe(false);
    expect(BrainFlow.params.safeParse({ Board: "x", Port: 1 }).success).toBe(false);
  });

  test("channel names per kind, axes for 3-axis sensors", () => {
    expect(channelNames(["exg", "accel", "package"], [2, 3, 1])).toEqual([
      "exg 1",
      "exg 2",
      "accel x",
      "accel y",
      "accel z",
      "package 1",
    ]);
  });

  test("a load error points at its param", () => {
    expect(paramOfError("brainflow has no board named 'x'; did you mean X_BOARD?")).toBe("Board");
    expect(paramOfError("brainflow has no master board named 'y'")).toBe("MasterBoard");
    expect(paramOfError("the playback and streaming boards need a master board (…)")).toBe(
      "MasterBoard",
    );
    expect(paramOfError("the board has no gyro channels")).toBe("Channels");
    expect(paramOfError("the playback file /a/b.csv does not exist")).toBe("File");
  });

  test("status words for each state", () => {
    const t = "board CYTON_BOARD (/dev/ttyUSB0)";
    expect(stateText(counts(BoardState.Connecting), t, "")).toBe(`connecting to ${t}…`);
    expect(stateText(counts(BoardState.Waiting, 2), t, "")).toBe(
      `waiting for data from ${t} (attempt 3)…`,
    );
    expect(stateText(counts(BoardState.Retrying, 1), t, "port missing")).toBe(
      "not streaming: port missing; retrying (attempt 2)",
    );
    expect(stateText(counts(BoardState.Ended), t, "")).toMatch(/playback file ended/);
  });

  test("without Python (the browser build) it loads, says so and emits nothing", async () => {
    const h = await BlockHarness.create(BrainFlow, { Board: "SYNTHETIC_BOARD" }, { io: {} });
    h.start();
    expect(h.text).toMatch(/needs Python/);
    expect(h.warnings.join("\n")).toMatch(/mosaic run or the desktop app/);
  });
});
