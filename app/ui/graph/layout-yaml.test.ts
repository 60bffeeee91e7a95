import { readFileSync } from "node:fs";
import { parseDocument } from "yaml";
import { describe, expect, it } from "vitest";
import { setBlockParam, updateLayout } from "./layout-yaml";

const SOURCE = `# yaml-language-server: $schema=schema/pipeline.schema.json
#
# A pipeline with comments everywhere.

Timer: { Type: ScheduledTimer, DesiredRate: 200 } # the clock

# The simulated armband.
Emg:
  Type: EmgSimulator
  Inputs: [Timer]
  Params:
    Channels: 8 # like a Myo
    Seed: 7
  # a comment after the last key
Rectify: { Type: Function, Inputs: [Emg], Params: { Operation: abs }, Layout: { X: 1, Y: 2 } }
LowPass:
  {
    Type: Filter,
    Inputs: [Rectify],
    Params: { Numerator: [0.0201, 0.0402, 0.0201], Denominator: [1, -1.561, 0.6414] },
  }
Sink:
  Type: Sink
  Layout:
    X: 10 # x
    Y: 20
  Inputs: ['LowPass']
Empty: {}
`;

const lines = (s: string) => s.split("\n");

describe("updateLayout (layout round trip)", () => {
  const positions = new Map([
    ["Timer", { x: 0.4, y: 100.6 }],
    ["Emg", { x: 290, y: 100 }],
    ["Rectify", { x: 580, y: 100 }],
    ["LowPass", { x: 870, y: 90 }],
    ["Sink", { x: 1160, y: -5 }],
    ["Empty", { x: 3, y: 4 }],
    ["NotInFile", { x: 1, y: 1 }],
  ]);
  const out = updateLayout(SOURCE, positions);

  it("writes every position, and the result loads with the same blocks in the same order", () => {
    const before = parseDocument(SOURCE).toJS() as Record<string, Record<string, unknown>>;
    const after = parseDocument(out).toJS() as Record<string, Record<string, unknown>>;
    expect(Object.keys(after)).toEqual(Object.keys(before));
    for (const [name, p] of positions) {
      if (name === "NotInFile") continue;
      expect(after[name]!.Layout, name).toEqual({ X: Math.round(p.x), Y: Math.round(p.y) });
      const { Layout: _a, ...restAfter } = after[name]!;
      const { Layout: _b, ...restBefore } = before[name]!;
      expect(restAfter).toEqual(restBefore);
      // Key order inside the block is kept; a new Layout comes last.
      const keysBefore = Object.keys(before[name]!);
      const expected = keysBefore.includes("Layout") ? keysBefore : [...keysBefore, "Layout"];
      expect(Object.keys(after[name]!)).toEqual(expected);
    }
    expect(Object.keys(after.Sink!)).toEqual(["Type", "Layout", "Inputs"]);
  });

  it("keeps every comment and every other line byte for byte", () => {
    const a = lines(SOURCE);
    const b = lines(out);
    // Exactly one line was added (Emg's new Layout), right after its last key.
    expect(b.length).toBe(a.length + 1);
    const added = b.indexOf("  Layout: { X: 290, Y: 100 }");
    expect(added).toBe(a.indexOf("    Seed: 7") + 1);
    const b2 = [...b.slice(0, added), ...b.slice(added + 1)];
    const changed = a.map((l, i) => (l === b2[i] ? null : i)).filter((i) => i !== null);
    const changedText = changed.map((i) => a[i!]!);
    // Only the lines that hold a Layout (or get one) differ.
    expect(changedText).toEqual([
      "Timer: { Type: ScheduledTimer, DesiredRate: 200 } # the clock",
      "Rectify: { Type: Function, Inputs: [Emg], Params: { Operation: abs }, Layout: { X: 1, Y: 2 } }",
      "    Params: { Numerator: [0.0201, 0.0402, 0.0201], Denominator: [1, -1.561, 0.6414] },",
      "    X: 10 # x",
      "    Y: 20",
      "Empty: {}",
    ]);
    for (const i of changed) expect(b2[i!]).toMatch(/[XY]: -?\d/);
    expect(b2[changed[0]!]).toBe(
      "Timer: { Type: ScheduledTimer, DesiredRate: 200, Layout: { X: 0, Y: 101 } } # the clock",
    );
    expect(b2[changed[1]!]).toBe(
      "Rectify: { Type: Function, Inputs: [Emg], Params: { Operation: abs }, Layout: { X: 580, Y: 100 } }",
    );
    expect(b2[changed[3]!]).toBe("    X: 1160 # x");
    expect(b2[changed[4]!]).toBe("    Y: -5");
    expect(b2[changed[5]!]).toBe("Empty: { Layout: { X: 3, Y: 4 } }");
    for (const c of SOURCE.match(/#.*$/gm)!) expect(out).toContain(c);
  });

  it("is idempotent and changes nothing when nothing moved", () => {
    expect(updateLayout(out, positions)).toBe(out);
    expect(updateLayout(SOURCE, new Map())).toBe(SOURCE);
  });

  it("round-trips the example pipelines: only Layout lines change", () => {
    for (const file of ["pipelines/demo.yaml", "pipelines/bench/myo.yaml"]) {
      const src = readFileSync(file, "utf8");
      const doc = parseDocument(src).toJS() as Record<string, unknown>;
      const pos = new Map(Object.keys(doc).map((k, i) => [k, { x: i * 10, y: i * 20 }]));
      const once = updateLayout(src, pos);
      const added = lines(once).filter((l) => !lines(src).includes(l));
      for (const l of added) expect(l, file).toMatch(/Layout: \{ X: -?\d+, Y: -?\d+ \}/);
      // Removing what was added gives the file back.
      const layout = "Layout: \\{ X: -?\\d+, Y: -?\\d+ \\}";
      const stripped = once
        .replace(new RegExp(`^ +${layout}\\n`, "gm"), "")
        .replace(new RegExp(`, ${layout}`, "g"), "");
      expect(stripped, file).toBe(src);
      const moved = new Map([...pos].map(([k, p]) => [k, { x: p.x + 5, y: p.y + 7 }]));
      const twice = updateLayout(once, moved);
      expect(lines(twice).length).toBe(lines(once).length);
      const js = parseDocument(twice).toJS() as Record<string, { Layout: unknown }>;
      for (const [k, p] of moved) expect(js[k]!.Layout).toEqual({ X: p.x, Y: p.y });
    }
  });

  it("refuses a file that is not a mapping", () => {
    expect(() => updateLayout("- a\n- b\n", new Map())).toThrow(/not a mapping/);
  });
});

describe("setBlockParam (a param edited in the form, written into the file)", () => {
  it("replaces a value in a flow mapping, keeping the rest of the line", () => {
    const out = setBlockParam(SOURCE, "Rectify", "Operation", "power");
    expect(out).toBe(SOURCE.replace("Params: { Operation: abs }", "Params: { Operation: power }"));
  });

  it("adds a param to a block mapping on its own line, and Params when there are none", () => {
    const out = setBlockParam(SOURCE, "Emg", "Gesture", "fist");
    expect(lines(out).length).toBe(lines(SOURCE).length + 1);
    expect(out).toContain("    Seed: 7\n    Gesture: fist\n  # a comment after the last key");
    const t = setBlockParam(SOURCE, "Timer", "Note", "x y");
    expect(lines(t)[4]).toBe(
      "Timer: { Type: ScheduledTimer, DesiredRate: 200, Params: { Note: x y } } # the clock",
    );
  });

  it("replaces a block-style value (a list) and keeps the next key on its line", () => {
    const src =
      "Emg:\n  Type: EmgSimulator\n  Params:\n    Sequence:\n      - { Gesture: rest, Seconds: 2 }\n    Seed: 7 # s\n";
    const out = setBlockParam(src, "Emg", "Sequence", [{ Gesture: "fist", Seconds: 1 }]);
    expect(out).toBe(
      "Emg:\n  Type: EmgSimulator\n  Params:\n    Sequence:\n      [{ Gesture: fist, Seconds: 1 }]\n    Seed: 7 # s\n",
    );
    expect(parseDocument(out).toJS()).toEqual({
      Emg: {
        Type: "EmgSimulator",
        Params: { Sequence: [{ Gesture: "fist", Seconds: 1 }], Seed: 7 },
      },
    });
  });

  it("quotes what YAML would read differently and refuses positional Params", () => {
    const out = setBlockParam(SOURCE, "Rectify", "Value", "5");
    expect(
      (parseDocument(out).toJS() as { Rectify: { Params: { Value: unknown } } }).Rectify.Params
        .Value,
    ).toBe("5");
    expect(() =>
      setBlockParam("A: { Type: X, Params: ['multiply:5'] }\n", "A", "Value", 2),
    ).toThrow(/positional/);
    expect(() => setBlockParam(SOURCE, "Nope", "Value", 2)).toThrow(/no block 'Nope'/);
  });
});
