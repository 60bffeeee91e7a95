import { readFileSync } from "node:fs";
import { parseDocument } from "yaml";
import { describe, expect, test } from "vitest";
import type { GraphInfo } from "../../engine/protocol";
import { matchingNames } from "./find";
import {
  NO_BOXES,
  initialBoxes,
  newBox,
  nodesInside,
  rememberBoxes,
  removeBox,
  updateBox,
  type Boxes,
} from "./boxes";
import { updateLayout } from "./layout-yaml";

const node = (id: string, x: number, y: number) => ({ id, x, y, width: 184, height: 92 });

describe("group membership is the picture", () => {
  const group = { x: 0, y: 0, width: 400, height: 200 };
  test("nodes wholly inside (a pixel of slack at the edges) belong to it, others not", () => {
    const nodes = [
      node("In", 10, 10),
      node("Edge", 216.5, 108.5), // right and bottom edges 0.5 px outside
      node("Across", 300, 10),
      node("Out", 500, 500),
    ];
    expect(nodesInside(group, nodes)).toEqual(["In", "Edge"]);
  });
});

describe("box edits", () => {
  const boxes: Boxes = {
    groups: [{ title: "A", x: 0, y: 0, width: 10, height: 10 }],
    comments: [{ text: "c", x: 1, y: 2, width: 30, height: 40 }],
  };
  test("a new box starts where asked, in whole pixels, at its kind's size", () => {
    expect(newBox("comment", { x: 100.4, y: -50.6 })).toEqual({
      x: 100,
      y: -51,
      width: 240,
      height: 110,
    });
  });
  test("update and remove touch one item and leave the input alone", () => {
    const renamed = updateBox(boxes, "group", 0, () => ({ title: "B", x: 5 }));
    expect(renamed.groups).toEqual([{ title: "B", x: 5, y: 0, width: 10, height: 10 }]);
    expect(renamed.comments).toBe(boxes.comments);
    expect(boxes.groups[0]!.title).toBe("A");
    expect(removeBox(boxes, "comment", 0)).toEqual({ groups: boxes.groups, comments: [] });
  });
  test("the boxes of a file are kept across reloads of it, not of another file", () => {
    const g = (file: string, layout?: Boxes): GraphInfo => ({
      file,
      blocks: [],
      ...(layout ? { layout } : {}),
    });
    expect(initialBoxes(g("a.yaml"))).toEqual(NO_BOXES);
    rememberBoxes(g("a.yaml"), boxes);
    expect(initialBoxes(g("a.yaml"))).toBe(boxes);
    // The file's own Layout changed (opened again after saving): the file wins.
    const saved = { groups: [], comments: boxes.comments };
    expect(initialBoxes(g("a.yaml", saved))).toBe(saved);
    expect(initialBoxes(g("b.yaml"))).toEqual(NO_BOXES);
  });
});

describe("search", () => {
  test("names containing the text, any case, in graph order; nothing for blank", () => {
    const names = ["Timer", "Emg", "Amplification", "Rectification", "LowPass"];
    expect(matchingNames(names, "TI")).toEqual(["Timer", "Amplification", "Rectification"]);
    expect(matchingNames(names, "  ")).toEqual([]);
    expect(matchingNames(names, "xyz")).toEqual([]);
  });
});

describe("Save layout writes positions and boxes; nothing else changes", () => {
  const demo = readFileSync("pipelines/demo.yaml", "utf8");
  const boxes: Boxes = {
    groups: [{ title: "Acquisition", x: -30.4, y: 40, width: 538, height: 260 }],
    comments: [{ text: "two\nlines: # kept", x: 840, y: 61, width: 240, height: 110 }],
  };
  test("the demo with a group and a comment: its comment lines all kept, Layout read back", () => {
    const out = updateLayout(demo, new Map([["Timer", { x: 1, y: 2 }]]), boxes);
    for (const line of demo.split("\n").filter((l) => l.startsWith("#")))
      expect(out).toContain(line);
    const js = parseDocument(out).toJS() as {
      Timer: { Layout: unknown };
      Pipeline: { Layout: unknown };
    };
    expect(js.Timer.Layout).toEqual({ X: 1, Y: 2 });
    expect(js.Pipeline.Layout).toEqual({
      Groups: [{ Title: "Acquisition", X: -30, Y: 40, Width: 538, Height: 260 }],
      Comments: [{ Text: "two\nlines: # kept", X: 840, Y: 61, Width: 240, Height: 110 }],
    });
  });
  test("saving the same boxes again changes nothing; no boxes leave a file without them", () => {
    const once = updateLayout(demo, new Map(), boxes);
    expect(updateLayout(once, new Map(), boxes)).toBe(once);
    expect(updateLayout(demo, new Map(), NO_BOXES)).toBe(demo);
    // The file's own key order and spacing count for nothing when the values are the same.
    const reordered = once.replace(
      "- { Title: Acquisition, X: -30,",
      "- {  X: -30, Title: Acquisition,",
    );
    expect(reordered).not.toBe(once);
    expect(updateLayout(reordered, new Map(), boxes)).toBe(reordered);
  });
});
