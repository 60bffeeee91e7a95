import { describe, expect, test } from "vitest";
import { isParticipantUrl, participantPlacement, type DisplayLike } from "./participant-window";

const laptop: DisplayLike = {
  id: 1,
  bounds: { x: 0, y: 0, width: 1440, height: 900 },
  workArea: { x: 0, y: 25, width: 1440, height: 875 },
};
const monitor: DisplayLike = {
  id: 2,
  bounds: { x: 1440, y: -180, width: 1920, height: 1080 },
  workArea: { x: 1440, y: -180, width: 1920, height: 1040 },
};

describe("participant window (desktop app)", () => {
  test("only the app's own participant page is opened as a participant window", () => {
    expect(isParticipantUrl("app://mosaic/index.html?view=participant&block=Cues")).toBe(true);
    expect(isParticipantUrl("app://mosaic/index.html?pipeline=x.yaml")).toBe(false);
    expect(isParticipantUrl("https://example.com/?view=participant")).toBe(false);
    expect(isParticipantUrl("app://other/index.html?view=participant")).toBe(false);
    expect(isParticipantUrl("not a url")).toBe(false);
  });

  test("full screen on the display the clinician's window is not on", () => {
    expect(participantPlacement([laptop, monitor], laptop)).toEqual({
      bounds: monitor.bounds,
      fullscreen: true,
    });
    expect(participantPlacement([laptop, monitor], monitor)).toEqual({
      bounds: laptop.bounds,
      fullscreen: true,
    });
  });

  test("with one display: a window centred in its work area, no larger than the display", () => {
    expect(participantPlacement([laptop], laptop)).toEqual({
      bounds: { x: 80, y: 63, width: 1280, height: 800 },
      fullscreen: false,
    });
    const small = { ...laptop, workArea: { x: 0, y: 0, width: 1024, height: 700 } };
    expect(participantPlacement([small], small).bounds).toEqual({
      x: 0,
      y: 0,
      width: 1024,
      height: 700,
    });
  });
});
