import fc from "fast-check";
import { parseDocument } from "yaml";
import { describe, expect, test } from "vitest";
import { relaxFlowLayout } from "./yaml-compat";

const parse = (text: string) => parseDocument(text, { uniqueKeys: true, prettyErrors: false });
const errorsOf = (text: string) => parse(text).errors.map((e) => e.code);

/** The pre-pass, checked: same length, and the relaxed text parses to `want`. */
function relaxed(src: string, want: unknown): string {
  const r = relaxFlowLayout(src);
  expect(r.text).toHaveLength(src.length);
  const d = parse(r.text);
  expect(d.errors).toEqual([]);
  expect(d.toJS()).toEqual(want);
  return r.text;
}

describe("relaxFlowLayout: what `yaml` rejects and the original's parser read", () => {
  test("a `]}` in column 1 closing a list inside a mapping (yaml: BAD_INDENT)", () => {
    const src = "A: { T: x, P: [\n    a:0,\n    b:1\n]}\n";
    expect(errorsOf(src)[0]).toBe("BAD_INDENT");
    const r = relaxFlowLayout(src);
    expect(r.fixes).toEqual([{ kind: "join", offset: src.lastIndexOf("\n]") }]);
    expect(relaxed(src, { A: { T: "x", P: ["a:0", "b:1"] } })).toBe(
      "A: { T: x, P: [\n    a:0,\n    b:1 ]}\n",
    );
  });

  test("more keys after the `]` in column 1, and a trailing comma before it", () => {
    relaxed("A: { P: [\n  a:0,\n  b:1,\n], Path: 'x' }\n", { A: { P: ["a:0", "b:1"], Path: "x" } });
  });

  test("a nested mapping closed by `}}` in column 1", () => {
    relaxed("A: { T: x, P: {\n  a: 1\n}}\n", { A: { T: "x", P: { a: 1 } } });
  });

  test("a comment at the end of the line above is blanked (it would swallow the bracket)", () => {
    const src = "A: { P: [\n  a:0  # the first\n]}\nB: { P: 1 }\n";
    const text = relaxed(src, { A: { P: ["a:0"] }, B: { P: 1 } });
    expect(text).toBe(src.replace("# the first\n", " ".repeat(12)));
  });

  test("a whole-line comment or a blank line above the bracket", () => {
    relaxed("A: { P: [\n  a:0,\n  # the end\n]}\n", { A: { P: ["a:0"] } });
    relaxed("A: { P: [\n  a:0\n\n]}\n", { A: { P: ["a:0"] } });
  });

  test("CRLF line endings: the two characters of the break become spaces", () => {
    const src = "A: { P: [\r\n  a:0\r\n]}\r\n";
    expect(relaxed(src, { A: { P: ["a:0"] } })).toBe("A: { P: [\r\n  a:0  ]}\r\n");
  });

  test("blocks nested in a block mapping need the deeper indentation", () => {
    relaxed("A:\n  P: { x: [\n    1\n  ]}\n", { A: { P: { x: [1] } } });
  });

  test("tab-indented keys of a flow mapping (yaml: BAD_INDENT, TAB_AS_INDENT)", () => {
    const src = "A: {\n\tT: x,\n\tI: [ b ], \n\t# a comment\n\tP: [ 1 ]\n} \n";
    expect(errorsOf(src)).toContain("TAB_AS_INDENT");
    const r = relaxFlowLayout(src);
    expect(r.fixes.map((f) => f.kind)).toEqual(["tab", "tab", "tab", "tab"]);
    expect(relaxed(src, { A: { T: "x", I: ["b"], P: [1] } })).toBe(src.replace(/\t/g, " "));
  });
});

describe("relaxFlowLayout: what it leaves alone", () => {
  test("valid files and the outermost `}` in column 1 (which yaml tolerates)", () => {
    for (const src of [
      "A: {\n  T: x\n}\n",
      "A: { T: x, P: [ 1, 2 ] }\nB:\n  - 1\n",
      "A: { P: [\n    1\n  ]\n}\n",
    ]) {
      expect(errorsOf(src)).toEqual([]);
      expect(relaxFlowLayout(src)).toEqual({ text: src, fixes: [] });
    }
  });

  test("a line that starts with anything but a closing bracket (a missing `]`)", () => {
    const src = "A: { T: x, P: [ 1, 2\nB: { T: y }\n";
    expect(relaxFlowLayout(src).fixes).toEqual([]);
  });

  test("tabs outside flow collections (indentation by tabs is an error there)", () => {
    const src = "A:\n\tT: x\n";
    expect(relaxFlowLayout(src).fixes).toEqual([]);
  });

  test("brackets inside quoted scalars, block scalars, comments and plain scalars", () => {
    for (const src of [
      "A: 'a [\n]b'\n",
      'A: "a {\\"\n}"\n',
      "A: |\n  [\n]\n",
      "A: a[1] # [\n]\n",
      "# {\n]\n",
      "A: { P: 'it''s [\n]' }\n",
    ]) {
      expect(relaxFlowLayout(src).fixes, src).toEqual([]);
    }
  });

  test("any text: same length, only tabs, line breaks and comment text become spaces", () => {
    const chars = [
      "A",
      ":",
      " ",
      "\t",
      "\n",
      "\r\n",
      "[",
      "]",
      "{",
      "}",
      ",",
      "#",
      "'",
      '"',
      "|",
      "-",
      "x",
    ];
    fc.assert(
      fc.property(fc.array(fc.constantFrom(...chars), { maxLength: 60 }), (parts) => {
        const src = parts.join("");
        const { text, fixes } = relaxFlowLayout(src);
        expect(text).toHaveLength(src.length);
        if (fixes.length === 0) expect(text).toBe(src);
        for (let i = 0; i < src.length; i++) {
          if (text[i] !== src[i]) expect(text[i]).toBe(" ");
        }
      }),
      { numRuns: 2000, seed: 13 },
    );
  });
});
