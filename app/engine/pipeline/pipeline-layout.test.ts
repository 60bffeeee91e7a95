/**
 * The pipeline's `Layout` section (`Pipeline: { Layout: { Groups, Comments } }`): read by the
 * loader with positioned errors, written by the document model without touching anything else.
 */
import { describe, expect, test } from "vitest";
import { formatDiagnostic } from "../diagnostics";
import { testCatalog } from "../test-blocks";
import { PipelineDocument } from "./document";
import { loadPipeline } from "./loader";
import { pipelineLayoutValue, type PipelineLayout } from "./pipeline-layout";

const BLOCKS = `# Two blocks and a comment.
T: { Type: Tick, DesiredRate: 10 } # the clock
S:
  Type: Drain
  Inputs: [T] # wired
`;

function load(src: string) {
  const r = loadPipeline(src, "p.yaml", testCatalog);
  return { r, messages: r.diagnostics.map(formatDiagnostic) };
}

const LAYOUT: PipelineLayout = {
  groups: [{ title: "Clock and sink", x: -20.4, y: -40, width: 420, height: 200.6 }],
  comments: [
    { text: "Ticks: 10 Hz, # not a comment", x: 300, y: 160, width: 200, height: 80 },
    { text: 'quotes "and" colons: kept', x: 0, y: 300, width: 150, height: 60 },
  ],
};

describe("reading Pipeline: { Layout }", () => {
  test("groups and comments load with the blocks, in canvas pixels", () => {
    const src = `${BLOCKS}Pipeline:
  BatchingMs: 2
  Layout:
    Groups:
      - { Title: Acquisition, X: -24, Y: -48, Width: 440, Height: 260 }
    Comments:
      - { Text: "Band-pass, then rectify", X: 480, Y: 300, Width: 220, Height: 90 }
      - { X: 0, Y: 0, Width: 10, Height: 10 }
`;
    const { r, messages } = load(src);
    expect(messages).toEqual([]);
    expect(r.spec!.blocks.map((b) => b.name)).toEqual(["T", "S"]);
    expect(r.spec!.settings.batchingMs).toBe(2);
    expect(r.spec!.settings.layout).toEqual({
      groups: [{ title: "Acquisition", x: -24, y: -48, width: 440, height: 260 }],
      comments: [
        { text: "Band-pass, then rectify", x: 480, y: 300, width: 220, height: 90 },
        { text: "", x: 0, y: 0, width: 10, height: 10 },
      ],
    });
  });

  test("a file without it has none (the original's files load as before)", () => {
    const { r, messages } = load(BLOCKS);
    expect(messages).toEqual([]);
    expect(r.spec!.settings.layout).toBeUndefined();
  });

  test("every bad value is one positioned error, with a suggestion for a misspelt key", () => {
    const src = `${BLOCKS}Pipeline:
  Layout:
    Groups:
      - { Title: A, X: 0, Y: 0, Width: -5, Height: 10 }
      - { Titel: B, X: 0, Y: 0, Width: 5, Height: 10 }
      - 7
    Coments: []
`;
    const { r, messages } = load(src);
    expect(r.ok).toBe(false);
    expect(messages).toEqual([
      expect.stringMatching(
        /^p\.yaml:9:40: error: Pipeline: Layout Groups\[0\]: Width is number -5/,
      ),
      expect.stringMatching(
        /^p\.yaml:10:11: error: Pipeline: Layout Groups\[1\]: unknown key 'Titel'.*did you mean 'Title'/s,
      ),
      expect.stringMatching(/^p\.yaml:11:9: error: Pipeline: Layout Groups\[2\] is number 7/),
      expect.stringMatching(
        /^p\.yaml:12:5: error: Pipeline: unknown Layout key 'Coments'.*did you mean 'Comments'/s,
      ),
    ]);
  });

  test("Layout that is not a mapping is refused", () => {
    const { messages } = load(`${BLOCKS}Pipeline: { Layout: [1, 2] }\n`);
    expect(messages).toEqual([
      expect.stringMatching(/^p\.yaml:6:21: error: Pipeline: Layout is a list/),
    ]);
  });
});

describe("writing it through the document model", () => {
  test("added at the end of a file without settings; everything before stays byte for byte", () => {
    const doc = PipelineDocument.parse(BLOCKS, "p.yaml");
    doc.setSetting("Layout", pipelineLayoutValue(LAYOUT));
    const out = doc.toString();
    expect(out.startsWith(BLOCKS)).toBe(true);
    expect(out.slice(BLOCKS.length)).toBe(
      [
        "Pipeline:",
        "  Layout:",
        "    Groups:",
        "      - { Title: Clock and sink, X: -20, Y: -40, Width: 420, Height: 201 }",
        "    Comments:",
        '      - { Text: "Ticks: 10 Hz, # not a comment", X: 300, Y: 160, Width: 200, Height: 80 }',
        "      - { Text: 'quotes \"and\" colons: kept', X: 0, Y: 300, Width: 150, Height: 60 }",
        "",
      ].join("\n"),
    );
    const { r, messages } = load(out);
    expect(messages).toEqual([]);
    expect(r.spec!.settings.layout).toEqual({
      groups: [{ title: "Clock and sink", x: -20, y: -40, width: 420, height: 201 }],
      comments: LAYOUT.comments,
    });
  });

  test("replaced in place in a block-style entry: other settings and comments kept", () => {
    const src = `${BLOCKS}# settings
Pipeline:
  Layout:
    Groups: [{ Title: Old, X: 0, Y: 0, Width: 1, Height: 1 }]
  BatchingMs: 3 # kept
# the end
`;
    const doc = PipelineDocument.parse(src, "p.yaml");
    doc.setSetting("Layout", pipelineLayoutValue({ groups: [], comments: LAYOUT.comments }));
    const out = doc.toString();
    expect(out).toContain("# settings\nPipeline:\n  Layout:\n    Comments:\n");
    expect(out).toContain("  BatchingMs: 3 # kept\n# the end\n");
    expect(out).not.toContain("Old");
    const { r, messages } = load(out);
    expect(messages).toEqual([]);
    expect(r.spec!.settings).toEqual({
      batchingMs: 3,
      layout: { groups: [], comments: LAYOUT.comments },
    });
  });

  test("a flow-style entry gets a one-line value", () => {
    const src = `${BLOCKS}Pipeline: { BatchingMs: 1 }\n`;
    const doc = PipelineDocument.parse(src, "p.yaml");
    doc.setSetting("Layout", pipelineLayoutValue({ groups: LAYOUT.groups, comments: [] }));
    expect(doc.toString()).toBe(
      `${BLOCKS}Pipeline: { BatchingMs: 1, Layout: { Groups: [{ Title: Clock and sink, X: -20, Y: -40, Width: 420, Height: 201 }] } }\n`,
    );
    expect(load(doc.toString()).messages).toEqual([]);
  });

  test("removing the last setting removes the entry; the file is as it was", () => {
    const doc = PipelineDocument.parse(BLOCKS, "p.yaml");
    doc.setSetting("Layout", pipelineLayoutValue(LAYOUT));
    expect(doc.setting("Layout")).toEqual(pipelineLayoutValue(LAYOUT));
    doc.setSetting("Layout", pipelineLayoutValue({ groups: [], comments: [] }));
    expect(doc.toString()).toBe(BLOCKS);
    expect(doc.setting("Layout")).toBeUndefined();
  });

  test("a block named Pipeline is not overwritten", () => {
    const src = `${BLOCKS}Pipeline: { Type: Drain, Inputs: [T] }\n`;
    const doc = PipelineDocument.parse(src, "p.yaml");
    expect(() => doc.setSetting("Layout", pipelineLayoutValue(LAYOUT))).toThrow(/is a block/);
    expect(doc.toString()).toBe(src);
  });
});
