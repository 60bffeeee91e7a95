/**
 * Loader stage 1, parse: YAML text → `yaml` Document (comments and node ranges kept) and a line
 * counter over the text as written; a syntax error becomes one positioned diagnostic.
 *
 * A file `yaml` rejects is parsed once more after the pre-pass of yaml-compat.ts (the layout of
 * multi-line flow collections the original MOSAIC accepted). The pre-pass keeps every offset, so
 * node ranges index the file as written and the editor (document.ts) edits it as it is. Files
 * that parse as they are never see the pre-pass.
 */
import { LineCounter, parseDocument, type Document } from "yaml";
import { Collector } from "./collector";
import type { SourcePos } from "./spec";
import { relaxFlowLayout, type LayoutFix } from "./yaml-compat";

export interface ParsedYaml {
  doc: Document;
  /** Fixes the pre-pass needed (none when the file parsed as it is). */
  fixes: LayoutFix[];
}

const OPTIONS = { uniqueKeys: true, prettyErrors: false } as const;

/** Parses pipeline YAML the way the loader and the editor do (see the file comment). */
export function parsePipelineYaml(source: string): ParsedYaml {
  const doc = parseDocument(source, OPTIONS);
  if (doc.errors.length === 0) return { doc, fixes: [] };
  const relaxed = relaxFlowLayout(source);
  if (relaxed.fixes.length === 0) return { doc, fixes: [] };
  return { doc: parseDocument(relaxed.text, OPTIONS), fixes: relaxed.fixes };
}

/** A line counter over `source` (1-based lines and columns for offsets). */
export function lineCounterOf(source: string): LineCounter {
  const lc = new LineCounter();
  lc.addNewLine(0);
  for (let i = source.indexOf("\n"); i >= 0; i = source.indexOf("\n", i + 1)) lc.addNewLine(i + 1);
  return lc;
}

export interface ParseStage {
  /** Undefined when the text could not be parsed at all. */
  doc: Document | undefined;
  /** False when the document has a syntax error (reported in `c`). */
  ok: boolean;
}

/** Stage 1: parses `source` and reports its first syntax error (the others are usually echoes). */
export function parseStage(c: Collector, source: string): ParseStage {
  let doc: Document;
  try {
    doc = parsePipelineYaml(source).doc;
  } catch (e) {
    c.error(
      "yaml-syntax",
      { line: 0, col: 0 },
      `cannot parse YAML: ${e instanceof Error ? e.message : String(e)}`,
    );
    return { doc: undefined, ok: false };
  }
  if (doc.errors.length === 0) return { doc, ok: true };
  const e = doc.errors[0]!;
  const d = syntaxDiagnostic(c, source, e.code, e.pos[0], e.message);
  c.error(d.code, d.at, d.message);
  return { doc, ok: false };
}

/** The diagnostic for one `yaml` error: its code, where it really is, and a readable message. */
export function syntaxDiagnostic(
  c: Collector,
  source: string,
  code: string,
  offset: number,
  message: string,
): { code: string; at: SourcePos; message: string } {
  let p = c.at(offset);
  const first = message.split("\n")[0] ?? message;
  let msg = `YAML syntax error: ${first}`;
  if (code === "DUPLICATE_KEY") {
    msg =
      "duplicate key: a block (or a key inside one) is defined twice; the second definition is here";
  } else if (code === "BLOCK_AS_IMPLICIT_KEY" || code === "MULTILINE_IMPLICIT_KEY") {
    // The parser notices this on the line above the culprit: point at the over-indented line.
    const lines = source.split(/\r?\n/);
    const indent = (l: string) => l.length - l.trimStart().length;
    const base = indent(lines[p.line - 1] ?? "");
    for (let i = p.line; i < lines.length; i++) {
      const l = lines[i]!;
      if (l.trim() === "" || l.trimStart().startsWith("#")) continue;
      if (indent(l) > base) p = { line: i + 1, col: indent(l) + 1 };
      break;
    }
    msg =
      "bad indentation: this line is indented further than the keys above it (the keys of one block must start in the same column)";
  } else if (code === "BAD_INDENT") {
    msg = `bad indentation: ${first}`;
  }
  return { code: code === "DUPLICATE_KEY" ? "duplicate-key" : "yaml-syntax", at: p, message: msg };
}
