import { describe, expect, test } from "vitest";
import type { BlockInfo, GraphInfo } from "../../engine/protocol";
import { gestureKind } from "./gesture-kind";
import { participantParams, participantUrl } from "./participant-link";
import { participantModel, type ModelInput, type StimulusLive } from "./participant-model";
import { heldOutTrigger, parseTriggerText, testCaptures } from "./test-schedule";

/** The protocol of pipelines/examples/training.yaml (labels numbered rest 0, fist 1, …). */
const PARAMS = {
  Labels: {
    rest: [0, 0],
    fist: [1, 0],
    open: [0, 1],
  },
  Repetitions: 3,
  Rest: 1.5,
  Rise: 0.5,
  Hold: 1,
  Capture: 3,
  Fall: 0.5,
};
const SESSION = {
  Labels: { fist: [1, 0], open: [0, 1] },
  Schedule: { Start: 120, Seconds: 3, Pause: 2, Repetitions: 2 },
};

const live = (s: Partial<StimulusLive>): StimulusLive => ({
  phase: undefined,
  phaseStart: NaN,
  cue: NaN,
  progress: undefined,
  text: "",
  lastT: NaN,
  ...s,
});
const input = (s: Partial<StimulusLive>, more: Partial<ModelInput> = {}): ModelInput => ({
  params: PARAMS,
  stimulus: live(s),
  test: undefined,
  engine: "running",
  now: 1000,
  fresh: true,
  ...more,
});
const test4 = (text: string, lastEventT = NaN) => ({
  captures: testCaptures(SESSION),
  text,
  lastEventT,
});

describe("participant screen model", () => {
  test("rest: relax, the next gesture, cue and repetition counts, the time left", () => {
    const m = participantModel(
      input({ phase: "rest", phaseStart: 999.5, progress: [4, 9, 2], text: "rest: open (4 of 9)" }),
    );
    expect(m).toMatchObject({
      screen: "rest",
      next: "open",
      instruction: "Relax",
      count: "Cue 4 of 9",
      repetition: "Repetition 2 of 3",
    });
    expect(m.left).toBeCloseTo(1, 9); // 1.5 s of rest, 0.5 s gone
    expect(m.progress).toBeCloseTo(1 / 3, 9);
  });

  test("a cue: the gesture, what to do in its phase, its countdown", () => {
    const m = participantModel(
      input({ phase: "capture", phaseStart: 998, cue: 1, progress: [7, 9, 2] }),
    );
    expect(m).toMatchObject({
      screen: "cue",
      phase: "capture",
      gesture: "fist",
      instruction: "Hold it — recording",
      count: "Cue 7 of 9",
      repetition: "Repetition 3 of 3",
    });
    expect(m.left).toBeCloseTo(1, 9);
    // A phase that began before the page watched: the status text's time left.
    const late = participantModel(
      input({ phase: "hold", cue: 2, text: "hold: open (2 of 9), 0.4 s left" }),
    );
    expect(late).toMatchObject({ screen: "cue", gesture: "open", left: 0.4 });
  });

  test("waiting before the protocol runs and while the engine is stopped", () => {
    expect(participantModel(input({ text: "ready: 9 cues (start to begin)" }))).toMatchObject({
      screen: "waiting",
      instruction: "The session starts soon",
    });
    expect(participantModel(input({ phase: "hold", cue: 1 }, { engine: "stopped" }))).toMatchObject(
      { screen: "waiting", instruction: "Paused" },
    );
    // Data that stopped coming (the protocol was stopped) is not shown as a cue.
    expect(participantModel(input({ phase: "hold", cue: 1 }, { fresh: false }))).toMatchObject({
      screen: "waiting",
      instruction: "Please wait",
    });
    // …unless the block's status says the protocol runs (data late on a busy machine).
    const late = input({ phase: "hold", cue: 1, text: "hold: fist (1 of 9), 0.5 s left" });
    expect(participantModel({ ...late, fresh: false })).toMatchObject({
      screen: "cue",
      gesture: "fist",
    });
  });

  test("after the protocol: the held-out test, cued as a test, then the end", () => {
    const ended = { phase: "end" as const, text: "done: 9 cues" };
    const ready = participantModel(
      input(ended, { test: test4("'fist' (1/2) selected, not capturing; schedule 0/4") }),
    );
    expect(ready).toMatchObject({ screen: "test-ready", next: "fist", count: "Test: 4 gestures" });
    const cue = participantModel(
      input(ended, {
        test: test4("capturing 'open' (2/2); schedule 2/4", 998),
        now: 1000,
      }),
    );
    expect(cue).toMatchObject({ screen: "test-cue", gesture: "open", count: "Test 2 of 4" });
    expect(cue.left).toBeCloseTo(1, 9); // 3 s captures
    const pause = participantModel(
      input(ended, {
        test: test4("'open' (2/2) selected, not capturing; schedule 2/4", 999.5),
        now: 1000,
      }),
    );
    expect(pause).toMatchObject({ screen: "test-rest", next: "fist", count: "Test 3 of 4 next" });
    expect(pause.left).toBeCloseTo(1.5, 9); // 2 s pauses
    const end = participantModel(
      input(ended, { test: test4("'open' (2/2) selected, not capturing; schedule 4/4") }),
    );
    expect(end).toMatchObject({ screen: "end", instruction: "Thank you!" });
    // Without a test, the protocol's end is the end.
    expect(participantModel(input(ended))).toMatchObject({ screen: "end" });
  });
});

const block = (b: Partial<BlockInfo> & { name: string; type: string }): BlockInfo => ({
  category: "Learning",
  summary: "",
  help: "",
  worker: "main",
  timer: false,
  desiredRate: 0,
  inputs: [],
  outputs: [],
  views: [],
  panel: "",
  live: [],
  params: {},
  paramsSchema: {},
  actions: [],
  ...b,
});
const fed = (name: string) => ({ source: name, block: name, port: "target", subscribed: true });

describe("held-out test schedule", () => {
  test("the scheduled Trigger that trains nothing is the test; one that feeds a learner is not", () => {
    const session = block({ name: "Session", type: "Trigger", params: SESSION });
    const graph: GraphInfo = {
      file: "t.yaml",
      blocks: [
        session,
        block({ name: "Myo", type: "EmgSimulator", category: "Sources", inputs: [fed("Session")] }),
      ],
    };
    expect(heldOutTrigger(graph)?.name).toBe("Session");
    const trained: GraphInfo = {
      ...graph,
      blocks: [
        ...graph.blocks,
        block({ name: "P", type: "IncrementalPredictor", inputs: [fed("Session")] }),
      ],
    };
    expect(heldOutTrigger(trained)).toBeUndefined();
  });

  test("captures of both schedule forms, with the pauses between them", () => {
    expect(testCaptures(SESSION)).toEqual([
      { label: "fist", seconds: 3, pauseAfter: 2 },
      { label: "open", seconds: 3, pauseAfter: 2 },
      { label: "fist", seconds: 3, pauseAfter: 2 },
      { label: "open", seconds: 3, pauseAfter: NaN },
    ]);
    expect(
      testCaptures({
        Labels: SESSION.Labels,
        Schedule: [
          { Label: "open", At: 10, Seconds: 2 },
          { Label: "fist", At: 4, Seconds: 1 },
        ],
      }),
    ).toEqual([
      { label: "fist", seconds: 1, pauseAfter: 5 },
      { label: "open", seconds: 2, pauseAfter: NaN },
    ]);
  });

  test("the Trigger's status text: the label it captures and the schedule's count", () => {
    expect(parseTriggerText("capturing 'fist' (1/5); schedule 3/10")).toEqual({
      capturing: "fist",
      done: 3,
      total: 10,
    });
    expect(parseTriggerText("'open' (2/5) selected, not capturing")).toEqual({
      capturing: undefined,
      done: undefined,
      total: undefined,
    });
  });
});

describe("gesture drawings and the participant URL", () => {
  test("names and synonyms find their drawing; an unknown name has none", () => {
    expect(gestureKind("fist")).toBe("fist");
    expect(gestureKind("Hand close")).toBe("fist");
    expect(gestureKind("wrist_flexion")).toBe("flexion");
    expect(gestureKind("Extension")).toBe("extension");
    expect(gestureKind("tripod")).toBe("pinch");
    expect(gestureKind("thumbs-up")).toBe("thumb");
    expect(gestureKind("task1")).toBeUndefined();
    expect(gestureKind("")).toBeUndefined();
  });

  test("the participant URL keeps the token, drops the pipeline and names the block", () => {
    const url = participantUrl("http://127.0.0.1:8321/?token=abc&pipeline=x.yaml#top", "Cues");
    expect(url).toBe("http://127.0.0.1:8321/?token=abc&view=participant&block=Cues");
    expect(participantParams(new URL(url).search)).toEqual({ block: "Cues", relay: undefined });
    const relayed = participantUrl("http://h/", "Cues", "r42");
    expect(participantParams(new URL(relayed).search)).toEqual({ block: "Cues", relay: "r42" });
    expect(participantParams("?pipeline=x.yaml")).toBeUndefined();
  });
});
