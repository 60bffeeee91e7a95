import { readdirSync, readFileSync, statSync } from "node:fs";
import { join } from "node:path";
import fc from "fast-check";
import { describe, expect, it } from "vitest";
import type { Catalog } from "../catalog";
import { testCatalog } from "../test-blocks";
import { DocumentHistory, PipelineDocument, flowYaml, referencedBlock } from "./document";
import { parsePipelineYaml } from "./parse";

const ROOT = join(__dirname, "../../..");
const FIXTURES = join(__dirname, "fixtures");
/** Our own files in the original MOSAIC's layouts (tests/integration/mosaic-original.test.ts). */
const MOSAIC_FIXTURES = join(ROOT, "tests/fixtures/mosaic-original");

function yamlFiles(dir: string): string[] {
  const out: string[] = [];
  for (const name of readdirSync(dir).sort()) {
    const p = join(dir, name);
    if (statSync(p).isDirectory()) {
      if (name !== "data" && name !== "schema") out.push(...yamlFiles(p));
    } else if (name.endsWith(".yaml") || name.endsWith(".yml")) out.push(p);
  }
  return out;
}

/** Inline sources for styles prettier would rewrite in a fixture file. */
const INLINE: Record<string, string> = {
  "padded-lists.yaml": `# MOSAIC style: padded lists, single quotes, a multi-line flow block, no final newline
timerFast: { Type: ScheduledTimer, DesiredRate: 2000 }
timerSlow: { Type: DecimatorTimer, DesiredRate: 200, Inputs: [ timerFast ] }
sinusoid: { Type: SinGenerator, Inputs: [ timerSlow ], Params: [ 6, 2.5, 1.5, 0.3 ] }
'squared': { Type: Function, Inputs: [ 'sinusoid' ], Params: [ power:2 ] }
ARV_LPF: {
  Type: Filter,
  Inputs: [ squared ],
  # 2nd-order Butterworth low-pass
  Params: [ 0.00094469;0.0018894;0.00094469, 1;-1.9112;0.91498 ]
}
joined: { Type: Joiner, Inputs: [ ARV_LPF, -squared, timerSlow ], Params: [ "timerBlockName:timerSlow" ] }
sink: { Type: Sink, Inputs: [ joined ] }`,
  "empty-with-comment.yaml": "# a new pipeline\n",
};

interface Case {
  name: string;
  text: string;
}

const CASES: Case[] = [
  ...yamlFiles(join(ROOT, "pipelines")).map((f) => ({
    name: f.slice(ROOT.length),
    text: readFileSync(f, "utf8"),
  })),
  ...readdirSync(FIXTURES)
    .filter((f) => f.endsWith(".yaml"))
    .map((f) => ({ name: `fixtures/${f}`, text: readFileSync(join(FIXTURES, f), "utf8") })),
  ...yamlFiles(MOSAIC_FIXTURES).map((f) => ({
    name: f.slice(ROOT.length),
    text: readFileSync(f, "utf8"),
  })),
  ...Object.entries(INLINE).map(([name, text]) => ({ name: `inline/${name}`, text })),
];
/** Every case once more with CRLF line endings (kept as they are: new lines use CRLF too). */
const ALL: Case[] = [
  ...CASES,
  ...CASES.map((c) => ({ name: `${c.name} (CRLF)`, text: c.text.replace(/\r?\n/g, "\r\n") })),
];

const lines = (s: string) => s.split(/\r?\n/);
/** Indices of lines that differ when both texts have the same number of lines. */
function changedLines(a: string, b: string): number[] {
  const x = lines(a);
  const y = lines(b);
  expect(y.length).toBe(x.length);
  return x.map((l, i) => (l === y[i] ? -1 : i)).filter((i) => i >= 0);
}
/**
 * YAML-level problems only: engine tests may not import the block catalog (mosaic/layers), so
 * the checks that the loader accepts the edited files with the real catalog are in
 * tests/integration/format.test.ts.
 */
const errorsOf = (text: string, _file = "p.yaml") => parsePipelineYaml(text).doc.errors;
/** Function's positional form, as app/blocks/signal/function.ts converts it (enough for the test). */
const catalog = new Map([
  [
    "Function",
    {
      type: "Function",
      legacyParams: (args: string[]) => {
        const [op, v] = (args[0] ?? "").split(":");
        return op === "power" ? { Operation: op, Exponent: Number(v) } : { Operation: op };
      },
    },
  ],
]) as unknown as Catalog;
const okFiles = ALL.filter((c) => !c.name.includes("empty"));

describe("PipelineDocument: round trip", () => {
  it("has something to test: every example and fixture (and CRLF twins)", () => {
    expect(CASES.length).toBeGreaterThan(20);
    for (const c of ALL) expect(errorsOf(c.text), c.name).toEqual([]);
  });

  it.each(ALL.map((c) => [c.name, c] as const))(
    "parse → serialise is byte-identical: %s",
    (_n, c) => {
      const doc = PipelineDocument.parse(c.text, c.name);
      expect(doc.toString()).toBe(c.text);
      // Edits that change nothing leave nothing changed.
      for (const b of doc.blockNames()) {
        doc.renameBlock(b, b);
        const info = doc.block(b);
        doc.setInputs(b, info.inputs);
        if (info.layout) doc.setLayout(b, info.layout);
      }
      expect(doc.toString()).toBe(c.text);
    },
  );

  it.each(okFiles.map((c) => [c.name, c] as const))(
    "a one-param edit changes exactly one line: %s",
    (_n, c) => {
      const doc = PipelineDocument.parse(c.text, c.name);
      let tried = 0;
      for (const b of doc.blockNames()) {
        const info = doc.block(b);
        if (info.positionalParams || !info.params) continue;
        for (const [k, v] of Object.entries(info.params)) {
          if (typeof v !== "number" && typeof v !== "string" && typeof v !== "boolean") continue;
          const d = PipelineDocument.parse(c.text, c.name);
          const nv = typeof v === "number" ? v + 1 : typeof v === "boolean" ? !v : `${v}x`;
          d.setParam(b, k, nv);
          const changed = changedLines(c.text, d.toString());
          expect(changed, `${b}.${k}`).toHaveLength(1);
          expect((d.block(b).params as Record<string, unknown>)[k]).toEqual(nv);
          // Every other block reads the same.
          for (const o of doc.blockNames()) if (o !== b) expect(d.block(o)).toEqual(doc.block(o));
          d.setParam(b, k, v);
          expect(parsePipelineYaml(d.toString()).doc.toJS()).toEqual(
            parsePipelineYaml(c.text).doc.toJS(),
          );
          tried++;
        }
      }
      if (doc.blockNames().some((b) => !doc.block(b).positionalParams && doc.block(b).params)) {
        expect(tried).toBeGreaterThan(0);
      }
    },
  );

  it.each(okFiles.map((c) => [c.name, c] as const))(
    "rename changes only the name and reference lines, and the file still loads: %s",
    (_n, c) => {
      const doc = PipelineDocument.parse(c.text, c.name);
      for (const b of doc.blockNames()) {
        const d = PipelineDocument.parse(c.text, c.name);
        const to = d.freshName(`${b}_renamed`);
        d.renameBlock(b, to);
        const out = d.toString();
        const changed = changedLines(c.text, out);
        const a = lines(c.text);
        // Every changed line is the old line with the name replaced (key or references).
        const renamed = new RegExp(`(?<![A-Za-z0-9_])${to}(?![A-Za-z0-9_])`, "g");
        for (const i of changed) {
          expect(lines(out)[i]!.replace(renamed, b)).toBe(a[i]);
        }
        expect(errorsOf(out, c.name), `${c.name}: rename ${b}`).toEqual([]);
        expect(d.blockNames()).toEqual(doc.blockNames().map((n) => (n === b ? to : n)));
        for (const o of doc.blockNames()) {
          const after = d.block(o === b ? to : o);
          const want = doc
            .block(o)
            .inputs.map((s) =>
              referencedBlock(s) === b ? s.replace(new RegExp(`^(-?)${b}`), `$1${to}`) : s,
            );
          expect(after.inputs).toEqual(want);
        }
      }
    },
  );

  it.each(okFiles.map((c) => [c.name, c] as const))(
    "duplicate and add give files that load; remove keeps the others' lines: %s",
    (_n, c) => {
      const doc = PipelineDocument.parse(c.text, c.name);
      for (const b of doc.blockNames()) {
        const d = PipelineDocument.parse(c.text, c.name);
        const copy = d.freshName(b);
        d.duplicateBlock(b, copy);
        expect(errorsOf(d.toString(), c.name), `duplicate ${b}`).toEqual([]);
        // Only lines were added, in one place.
        const a = lines(c.text);
        const o = lines(d.toString());
        let i = 0;
        while (i < a.length && a[i] === o[i]) i++;
        expect(o.slice(i + o.length - a.length)).toEqual(a.slice(i));
        d.addBlock(d.freshName("Probe"), "Sink", { inputs: [copy], layout: { x: 1.4, y: 2.6 } });
        expect(errorsOf(d.toString(), c.name), `add after ${b}`).toEqual([]);

        const r = PipelineDocument.parse(c.text, c.name);
        let dropped;
        try {
          dropped = r.removeBlock(b);
        } catch (e) {
          // Removing the anchor that other blocks' aliases need is refused.
          expect((e as Error).message).toMatch(/alias \*\w+ has no anchor/);
          expect(r.toString()).toBe(c.text);
          continue;
        }
        expect(r.blockNames()).toEqual(doc.blockNames().filter((n) => n !== b));
        for (const o of r.blockNames()) {
          const before = doc.block(o);
          const after = r.block(o);
          expect(after.inputs).toEqual(before.inputs.filter((s) => referencedBlock(s) !== b));
          const lost = dropped
            .filter((x) => x.block === o && x.kind === "input")
            .map((x) => x.input);
          expect(lost).toEqual(before.inputs.filter((s) => referencedBlock(s) === b));
        }
        expect(r.lastDropped).toEqual(dropped);
        // The result is valid YAML whose other blocks are untouched unless they lost an input.
        const js = parsePipelineYaml(r.toString()).doc.toJS() as Record<string, unknown>;
        const js0 = parsePipelineYaml(c.text).doc.toJS() as Record<string, unknown>;
        for (const o of r.blockNames()) {
          if (!dropped.some((x) => x.block === o)) expect(js[o]).toEqual(js0[o]);
        }
      }
    },
  );
});

describe("PipelineDocument: edits on a commented file", () => {
  const src = readFileSync(join(FIXTURES, "commented.yaml"), "utf8");
  const parse = () => PipelineDocument.parse(src, "commented.yaml");

  it("keeps every comment through a series of edits and the result loads", () => {
    const d = parse();
    d.setParam("Emg", "Channels", 4);
    d.setParam("Emg", "Gesture", "fist");
    d.setParam("Rectify", "Operation", "power");
    d.renameBlock("Timer", "Clock");
    d.setDesiredRate("Clock", 100);
    d.setPath("Envelope", "logs/");
    d.setLayout("Emg", { x: 3.2, y: -4.7 });
    d.connect("Emg", "Device");
    d.addBlock("Extra", "Sink", { inputs: ["Pace"] });
    const out = d.toString();
    for (const comment of src.match(/#.*$/gm)!) expect(out).toContain(comment);
    expect(errorsOf(out)).toEqual([]);
    expect(out).toContain("Clock: { Type: ScheduledTimer, DesiredRate: 100 } # 200 Hz like a Myo");
    expect(out).toContain("    - Clock # the only input");
    expect(out).toContain("    Channels: 4 # like a Myo");
    expect(out).toContain(
      "      - { Gesture: fist, Seconds: 2 } # squeeze\n    Gesture: fist\n  Layout: { X: 3, Y: -5 }\n  # a comment after the last key of Emg",
    );
    expect(out).toContain("Envelope: { Type: Resampler, Inputs: [LowPass, Pace], Path: logs/ }");
    expect(out).toContain("Device: { Type: Sink, Inputs: [Joined, Emg] }");
    expect(out).toMatch(/Device: .*\nExtra: \{ Type: Sink, Inputs: \[Pace\] \}\n# The end\.\n$/);
  });

  it("renames every form of reference: -Name, Name.port, Trigger", () => {
    const d = parse();
    d.renameBlock("Pace", "Tick");
    d.renameBlock("Rectify", "Abs");
    const out = d.toString();
    expect(out).toContain("  Inputs: [Envelope, -Abs, Tick]\n  Params: { Trigger: Tick }");
    expect(out).toContain('Inputs: ["Abs"]');
    expect(errorsOf(out)).toEqual([]);
    const t = PipelineDocument.parse(
      "A: { Type: ScheduledTimer, DesiredRate: 1 }\nB: { Type: Sink, Inputs: [A.out, -A.out] }\n",
      "p",
    );
    t.renameBlock("A", "Z");
    expect(t.toString()).toBe(
      "Z: { Type: ScheduledTimer, DesiredRate: 1 }\nB: { Type: Sink, Inputs: [Z.out, -Z.out] }\n",
    );
  });

  it("removes a block with its inside comments, keeps the comments above it, drops references", () => {
    const d = parse();
    const dropped = d.removeBlock("Pace");
    expect(dropped).toEqual([
      { block: "Envelope", input: "Pace", kind: "input" },
      { block: "Joined", input: "Pace", kind: "input" },
      { block: "Joined", input: "Pace", kind: "trigger" },
    ]);
    const out = d.toString();
    expect(out).not.toContain("Pace");
    expect(out).not.toContain("# 25 Hz");
    expect(out).toContain("  Inputs: [Envelope, -Rectify]\nDevice:");
    const e = parse();
    e.removeBlock("Emg");
    expect(e.toString()).toContain(
      "# The simulated armband.\n\nRectify: { Type: Function, Params: { Operation: abs } }",
    );
    expect(e.toString()).not.toContain("# like a Myo");
  });

  it("removes params, keys and inputs in block and flow style", () => {
    const d = parse();
    d.removeParam("Emg", "Seed");
    d.removeParam("Gain", "Value");
    d.removeParam("Rectify", "Operation");
    d.removeParam("Rectify", "Operation"); // absent: nothing to do
    d.setDesiredRate("Pace", undefined);
    d.disconnect("Rectify", "Joined");
    const out = d.toString();
    expect(out).toContain("    Channels: 8 # like a Myo\n\n    # A comment between params");
    expect(out).toContain("    Params: { Operation: multiply },");
    expect(out).toContain("Rectify: { Type: Function, Inputs: [Emg] }\n");
    expect(out).toContain("Pace: { Type: DecimatorTimer, Inputs: [Timer] } # 25 Hz");
    expect(out).toContain("  Inputs: [Envelope, Pace]\n");
  });

  it("throws clear errors and changes nothing", () => {
    const d = parse();
    const cases: [() => void, RegExp][] = [
      [() => d.setParam("Nope", "X", 1), /no block 'Nope'/],
      [() => d.setParam("Emgg", "X", 1), /did you mean 'Emg'/],
      [() => d.addBlock("Emg", "Sink"), /exists already/],
      [() => d.addBlock("a.b", "Sink"), /not a valid block name/],
      [() => d.renameBlock("Emg", "Timer"), /exists already/],
      [() => d.renameBlock("Emg", "1x"), /not a valid block name/],
      [() => d.duplicateBlock("Emg", "Rectify"), /exists already/],
      [() => d.connect("Missing", "Device"), /no block 'Missing'/],
      [() => d.connect("Joined", "Device"), /already/],
      [() => d.disconnect("Emg", "Device"), /no input 'Emg'/],
      [() => d.setDesiredRate("Timer", -1), /positive/],
      [() => d.setLayout("Timer", { x: NaN, y: 0 }), /finite/],
      [() => d.setInputs("Device", ["bad name"]), /not an input/],
      [() => d.setParam("Emg", "F", () => 1), /cannot write/],
    ];
    for (const [f, re] of cases) expect(f).toThrow(re);
    expect(d.toString()).toBe(src);
  });

  it("adds keys in the usual order and writes values YAML reads back the same", () => {
    const d = PipelineDocument.parse("A:\n  Type: Sink\n  Params:\n    X: 1\n", "p");
    d.setDesiredRate("A", 5);
    d.setInputs(
      "A",
      ["B"].filter(() => false),
    );
    d.setParam("A", "S", "a, b: #c");
    d.setParam("A", "T", "true");
    d.setParam("A", "N", [1.5, -Infinity, NaN]);
    d.setParam("A", "M", { k: "line\nbreak", e: {} });
    d.setParam("A", "V", new Float64Array([1, 2]));
    expect(d.toString().split("\n").slice(0, 3)).toEqual([
      "A:",
      "  Type: Sink",
      "  DesiredRate: 5",
    ]);
    const js = parsePipelineYaml(d.toString()).doc.toJS() as {
      A: { Params: Record<string, unknown> };
    };
    expect(js.A.Params).toEqual({
      X: 1,
      S: "a, b: #c",
      T: "true",
      N: [1.5, -Infinity, NaN],
      M: { k: "line\nbreak", e: {} },
      V: [1, 2],
    });
    expect(flowYaml({ A: [1, "x"], B: {} })).toBe("{ A: [1, x], B: {} }");
  });
});

describe("PipelineDocument: positional Params, anchors, CRLF, empty files", () => {
  it("refuses to edit positional Params, and converts them on request", () => {
    const d = PipelineDocument.parse(INLINE["padded-lists.yaml"]!, "p.yaml");
    expect(() => d.setParam("sinusoid", "Frequency", 2)).toThrow(/positional.*convertLegacyParams/);
    expect(() => d.removeParam("sinusoid", "Frequency")).toThrow(/positional/);
    d.convertLegacyParams("squared", catalog);
    d.setParam("squared", "Value", 3);
    expect(d.toString()).toContain(
      "'squared': { Type: Function, Inputs: [ 'sinusoid' ], Params: { Operation: power, Exponent: 2, Value: 3 } }",
    );
    expect(() => d.convertLegacyParams("ARV_LPF", catalog)).toThrow(/unknown block type 'Filter'/);
    expect(() => d.convertLegacyParams("sink", catalog)).toThrow(/not positional/);
    d.renameBlock("timerSlow", "slow");
    expect(d.toString()).toContain('Params: [ "timerBlockName:slow" ]');
    expect(d.toString()).toContain("Inputs: [ slow ]");
    d.connect("sinusoid", "sink", 0);
    expect(d.toString()).toContain("sink: { Type: Sink, Inputs: [ sinusoid, joined ] }");
    // A file without a final line break stays without one (normalize() adds it).
    expect(d.toString().endsWith("] }")).toBe(true);
    expect(errorsOf(d.toString())).toEqual([]);
  });

  it("keeps anchors when the anchored value changes", () => {
    const src = readFileSync(join(FIXTURES, "anchors.yaml"), "utf8");
    const d = PipelineDocument.parse(src, "anchors.yaml");
    d.setParam("First", "Numerator", [0.1, 0.2, 0.1]);
    expect(d.toString()).toContain("    Numerator: &num [0.1, 0.2, 0.1] # shared");
    expect(errorsOf(d.toString())).toEqual([]);
    expect(d.block("Second").params).toEqual({
      Numerator: [0.1, 0.2, 0.1],
      Denominator: [1, -1.561, 0.6414],
    });
    d.duplicateBlock("Second", "Third");
    expect(errorsOf(d.toString())).toEqual([]);
  });

  it("keeps CRLF line endings and writes new lines with them", () => {
    const src = readFileSync(join(FIXTURES, "commented.yaml"), "utf8").replace(/\n/g, "\r\n");
    const d = PipelineDocument.parse(src, "c.yaml");
    d.setParam("Emg", "Gesture", "rest");
    d.addBlock("More", "Sink", { inputs: ["Emg"] });
    d.removeBlock("Gain");
    d.setInputs("LowPass", ["Rectify"]);
    expect(d.toString().replace(/\r\n/g, "")).not.toContain("\n");
    expect(errorsOf(d.toString())).toEqual([]);
  });

  it("builds a pipeline from an empty file and adds the final newline on normalize", () => {
    const d = PipelineDocument.parse("", "new.yaml");
    expect(d.blockNames()).toEqual([]);
    d.addBlock("Timer", "ScheduledTimer", { desiredRate: 50 });
    d.addBlock("Sink", "Sink", { inputs: ["Timer"], params: {}, layout: { x: 0, y: 0 } });
    expect(d.toString()).toBe(
      "Timer: { Type: ScheduledTimer, DesiredRate: 50 }\nSink: { Type: Sink, Inputs: [Timer], Layout: { X: 0, Y: 0 } }\n",
    );
    // The loader runs on the text (here with the engine's test catalog: unknown types, no syntax errors).
    expect(d.validate(testCatalog).map((x) => x.code)).toEqual(["unknown-type", "unknown-type"]);
    const c = PipelineDocument.parse("# new\n", "n.yaml");
    c.addBlock("T", "ScheduledTimer", { desiredRate: 1 });
    expect(c.toString()).toBe("# new\nT: { Type: ScheduledTimer, DesiredRate: 1 }\n");
    const n = PipelineDocument.parse("A: { Type: Sink }", "p");
    n.normalize();
    expect(n.toString()).toBe("A: { Type: Sink }\n");
    n.normalize();
    expect(n.toString()).toBe("A: { Type: Sink }\n");
  });

  it("refuses text that is not YAML or not a mapping", () => {
    expect(() => PipelineDocument.parse("A: [\n", "p")).toThrow(/YAML error at/);
    expect(() => PipelineDocument.parse("- a\n", "p")).toThrow(/not a mapping/);
    expect(() => PipelineDocument.parse("A: 1\nA: 2\n", "p")).toThrow(/YAML error/);
  });

  it("freshName gives unused, valid names", () => {
    const d = PipelineDocument.parse("Filter: { Type: Sink }\nFilter2: { Type: Sink }\n", "p");
    expect(d.freshName("Filter")).toBe("Filter3");
    expect(d.freshName("Filter2")).toBe("Filter3");
    expect(d.freshName("New")).toBe("New");
    expect(d.freshName("2 bad.name")).toBe("_2_bad_name");
  });
});

describe("DocumentHistory", () => {
  it("undoes and redoes, ignores no-op pushes, is capped", () => {
    const h = new DocumentHistory("a", 3);
    expect(h.canUndo).toBe(false);
    h.push("a");
    expect(h.canUndo).toBe(false);
    for (const s of ["b", "c", "d", "e"]) h.push(s);
    expect(h.undo()).toBe("d");
    expect(h.undo()).toBe("c");
    expect(h.undo()).toBe("b");
    expect(h.undo()).toBeUndefined();
    expect(h.current).toBe("b");
    expect(h.redo()).toBe("c");
    h.push("x");
    expect(h.canRedo).toBe(false);
    expect(h.redo()).toBeUndefined();
    h.reset("z");
    expect([h.current, h.canUndo, h.canRedo]).toEqual(["z", false, false]);
  });
});

describe("PipelineDocument: random edit sequences (fast-check)", () => {
  const bases = okFiles.filter((c) => !c.name.includes("CRLF")).slice();
  const types = ["Sink", "Function", "ScheduledTimer", "Filter", "Joiner", "Nope"];
  const name = fc.constantFrom(
    "Timer",
    "Emg",
    "New",
    "A",
    "Sink",
    "x-1",
    "bad.name",
    "Pace",
    "Joined",
  );
  const value = fc.oneof(
    fc.integer({ min: -5, max: 50 }),
    fc.double({ noNaN: false }),
    fc.string({ maxLength: 8 }),
    fc.boolean(),
    fc.array(fc.integer(), { maxLength: 4 }),
    fc.dictionary(fc.string({ minLength: 1, maxLength: 4 }), fc.integer(), { maxKeys: 2 }),
  );
  const op = fc.oneof(
    fc.record({
      k: fc.constant("add"),
      n: name,
      t: fc.constantFrom(...types),
      i: fc.array(name, { maxLength: 2 }),
    }),
    fc.record({ k: fc.constant("remove"), n: name }),
    fc.record({ k: fc.constant("rename"), n: name, to: name }),
    fc.record({ k: fc.constant("dup"), n: name, to: name }),
    fc.record({
      k: fc.constant("param"),
      n: name,
      p: fc.constantFrom("Operation", "Value", "Channels", "Trigger", "Q"),
      v: value,
    }),
    fc.record({
      k: fc.constant("unparam"),
      n: name,
      p: fc.constantFrom("Operation", "Value", "Channels", "Trigger"),
    }),
    fc.record({ k: fc.constant("connect"), n: name, to: name, i: fc.nat(3) }),
    fc.record({ k: fc.constant("disconnect"), n: name, to: name }),
    fc.record({ k: fc.constant("rate"), n: name, r: fc.option(fc.double({ min: -1, max: 1000 })) }),
    fc.record({ k: fc.constant("path"), n: name, s: fc.option(fc.string({ maxLength: 6 })) }),
    fc.record({
      k: fc.constant("layout"),
      n: name,
      x: fc.double({ min: -1e4, max: 1e4, noNaN: true }),
      y: fc.integer(),
    }),
  );
  type Op = typeof op extends fc.Arbitrary<infer T> ? T : never;

  function run(d: PipelineDocument, o: Op): void {
    switch (o.k) {
      case "add":
        return d.addBlock(o.n, o.t, { inputs: o.i });
      case "remove":
        d.removeBlock(o.n);
        return;
      case "rename":
        return d.renameBlock(o.n, o.to);
      case "dup":
        return d.duplicateBlock(o.n, o.to);
      case "param":
        return d.setParam(o.n, o.p, o.v);
      case "unparam":
        return d.removeParam(o.n, o.p);
      case "connect":
        return d.connect(o.n, o.to, o.i);
      case "disconnect":
        return d.disconnect(o.n, o.to);
      case "rate":
        return d.setDesiredRate(o.n, o.r ?? undefined);
      case "path":
        return d.setPath(o.n, o.s ?? undefined);
      case "layout":
        return d.setLayout(o.n, { x: o.x, y: o.y });
    }
  }

  it("every edit either throws a clear error (nothing changed) or gives a file the loader reads, with the untouched blocks as they were", () => {
    fc.assert(
      fc.property(fc.constantFrom(...bases), fc.array(op, { maxLength: 12 }), (c, ops) => {
        const d = PipelineDocument.parse(c.text, c.name);
        for (const o of ops) {
          const before = d.toString();
          const js0 = parsePipelineYaml(before).doc.toJS() as Record<string, unknown>;
          try {
            run(d, o);
          } catch (e) {
            expect(e).toBeInstanceOf(Error);
            expect((e as Error).message.length).toBeGreaterThan(5);
            expect((e as Error).message).not.toMatch(/undefined|\[object/);
            expect(d.toString()).toBe(before);
            continue;
          }
          const after = d.toString();
          // Valid YAML, a mapping of blocks; the loader gives diagnostics, never a syntax error.
          const diags = d.validate(testCatalog);
          expect(
            diags.filter((x) => ["yaml-syntax", "duplicate-key", "not-a-mapping"].includes(x.code)),
          ).toEqual([]);
          expect(PipelineDocument.parse(after, c.name).toString()).toBe(after);
          // Blocks the edit is not about read the same as before.
          const js = parsePipelineYaml(after).doc.toJS() as Record<string, unknown>;
          const about = new Set([o.n, "to" in o ? o.to : ""]);
          for (const [k, v] of Object.entries(js0)) {
            if (about.has(k) || !(k in js)) continue;
            const refs = JSON.stringify(v);
            if ([...about].some((n) => n && refs.includes(n))) continue;
            expect(js[k], `${o.k} ${k}`).toEqual(v);
          }
        }
      }),
      { numRuns: 150 },
    );
  });
});
