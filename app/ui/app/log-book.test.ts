import { describe, expect, test } from "vitest";
import type { Diagnostic } from "../../engine/diagnostics";
import {
  appendEntries,
  countsText,
  currentCounts,
  currentEntries,
  diagnosticLine,
  earlierEntries,
  EMPTY_LOG,
  loadLines,
  logFileName,
  logJsonLines,
  MAX_LOG,
  startLoad,
  type LogBook,
  type LogEntry,
  type LoadReport,
} from "./log-book";

const warning = (line: number, message = `w${line}`): Diagnostic => ({
  severity: "warning",
  code: "legacy-converted",
  message,
  file: "p.yaml",
  line,
  col: 3,
});
const error: Diagnostic = {
  severity: "error",
  code: "unknown-type",
  message: "unknown block type 'EmgSimulatr'",
  file: "p.yaml",
  line: 4,
  col: 14,
  suggestion: "EmgSimulator",
};

/** Plays a load report into the book as the hook does (ids from `next`). */
function load(book: LogBook, r: LoadReport, next: { id: number }): LogBook {
  const lines = loadLines(r).map((l) => ({ ...l, t: 0, id: next.id++ }));
  return r.replaced ? startLoad(book, lines, next.id) : appendEntries(book, lines);
}

function event(level: LogEntry["level"], next: { id: number }): LogEntry {
  return { id: next.id++, t: 0, level, block: "Emg", message: level };
}

describe("the event log's counts", () => {
  test("a load's warnings are in the log, counted as the banner counts them", () => {
    const next = { id: 1 };
    const diagnostics = [1, 2, 3, 4, 5, 6, 7, 8].map((l) => warning(l));
    const book = load(EMPTY_LOG, { file: "p.yaml", diagnostics, replaced: true }, next);
    expect(currentCounts(book)).toEqual({ errors: 0, warnings: 8, infos: 1 });
    expect(countsText(currentCounts(book))).toBe("8 warnings");
    const listed = currentEntries(book).filter((e) => e.level === "warning");
    expect(listed.map((e) => e.block)).toEqual(diagnostics.map((d) => `p.yaml:${d.line}:3`));
    expect(currentEntries(book)[0]!.message).toBe("loaded p.yaml: 8 warnings");
  });

  test("'no errors' is never said beside warnings; both are said plainly", () => {
    expect(countsText({ errors: 0, warnings: 1, infos: 0 })).toBe("1 warning");
    expect(countsText({ errors: 2, warnings: 3, infos: 0 })).toBe("2 errors, 3 warnings");
    expect(countsText({ errors: 1, warnings: 0, infos: 5 })).toBe("1 error");
    expect(countsText({ errors: 0, warnings: 0, infos: 5 })).toBe("no errors or warnings");
  });

  test("runtime events join the current load; a new load starts the counts again", () => {
    const next = { id: 1 };
    let book = load(EMPTY_LOG, { file: "a.yaml", diagnostics: [warning(1)], replaced: true }, next);
    book = appendEntries(book, [event("error", next), event("warning", next)]);
    expect(currentCounts(book)).toMatchObject({ errors: 1, warnings: 2 });
    book = load(book, { file: "b.yaml", diagnostics: [], replaced: true }, next);
    expect(currentCounts(book)).toMatchObject({ errors: 0, warnings: 0 });
    expect(currentEntries(book).map((e) => e.message)).toEqual([
      "loaded b.yaml: no errors or warnings",
    ]);
    // Earlier loads are kept, apart.
    expect(earlierEntries(book)).toHaveLength(4);
    book = appendEntries(book, [event("warning", next)]);
    expect(currentCounts(book)).toMatchObject({ errors: 0, warnings: 1 });
  });

  test("loading the same file twice counts its warnings once", () => {
    const next = { id: 1 };
    const r: LoadReport = { file: "a.yaml", diagnostics: [warning(1), warning(2)], replaced: true };
    const book = load(load(EMPTY_LOG, r, next), r, next);
    expect(currentCounts(book).warnings).toBe(2);
    expect(book.entries.filter((e) => e.level === "warning")).toHaveLength(4);
  });

  test("a load that fails counts its errors; a file that cannot be read adds to what runs", () => {
    const next = { id: 1 };
    let book = load(EMPTY_LOG, { file: "a.yaml", diagnostics: [warning(1)], replaced: true }, next);
    book = load(
      book,
      { file: "x.yaml", diagnostics: [], error: "HTTP 404", replaced: false },
      next,
    );
    expect(currentCounts(book)).toMatchObject({ errors: 1, warnings: 1 });
    book = load(book, { file: "p.yaml", diagnostics: [error, warning(2)], replaced: true }, next);
    expect(currentCounts(book)).toMatchObject({ errors: 1, warnings: 1 });
    expect(currentEntries(book)[0]!.message).toBe("p.yaml did not load: 1 error, 1 warning");
    expect(diagnosticLine({ ...error, file: "pipelines/legacy/p.yaml" }).block).toBe("p.yaml:4:14");
    expect(diagnosticLine(error)).toEqual({
      level: "error",
      block: "p.yaml:4:14",
      message: "unknown block type 'EmgSimulatr'; did you mean 'EmgSimulator'?",
    });
  });

  test("a pipeline adopted from a shared engine starts a section of its own", () => {
    const next = { id: 1 };
    let book = load(EMPTY_LOG, { file: "a.yaml", diagnostics: [warning(1)], replaced: true }, next);
    book = load(book, { file: "b.yaml", diagnostics: [], adopted: true, replaced: true }, next);
    expect(currentCounts(book).warnings).toBe(0);
    expect(currentEntries(book)[0]!.message).toContain("showing b.yaml");
  });

  test("the log keeps the newest entries only; the counts follow what it keeps", () => {
    const next = { id: 1 };
    let book = load(EMPTY_LOG, { file: "a.yaml", diagnostics: [], replaced: true }, next);
    const many = Array.from({ length: MAX_LOG + 20 }, () => event("warning", next));
    book = appendEntries(book, many);
    expect(book.entries).toHaveLength(MAX_LOG);
    expect(currentCounts(book).warnings).toBe(MAX_LOG);
  });
});

describe("the Log's download (JSON Lines)", () => {
  test("every entry, oldest first, one object per line, marked current or earlier", () => {
    const next = { id: 1 };
    let book = load(EMPTY_LOG, { file: "a.yaml", diagnostics: [warning(2)], replaced: true }, next);
    book = load(book, { file: "b.yaml", diagnostics: [error], replaced: true }, next);
    book = appendEntries(book, [
      {
        id: next.id++,
        t: 1_700_000_000.25,
        level: "info",
        block: "Pred",
        message: 'a "quoted"\nline',
      },
    ]);
    const text = logJsonLines(book);
    expect(text.endsWith("\n")).toBe(true);
    const rows = text
      .trimEnd()
      .split("\n")
      .map((l) => JSON.parse(l) as Record<string, unknown>);
    expect(rows.map((r) => [r.level, r.block, r.currentLoad])).toEqual([
      ["info", "", false],
      ["warning", "p.yaml:2:3", false],
      ["info", "", true],
      ["error", "p.yaml:4:14", true],
      ["info", "Pred", true],
    ]);
    expect(rows[0]!.message).toBe("loaded a.yaml: 1 warning");
    expect(rows[3]!.message).toBe("unknown block type 'EmgSimulatr'; did you mean 'EmgSimulator'?");
    // A message with quotes and a line break stays one line and reads back the same.
    expect(rows[4]).toEqual({
      time: "2023-11-14T22:13:20.250Z",
      t: 1_700_000_000.25,
      level: "info",
      block: "Pred",
      message: 'a "quoted"\nline',
      currentLoad: true,
    });
    expect(logJsonLines(EMPTY_LOG)).toBe("");
  });

  test("the file is named from the local date and time", () => {
    expect(logFileName(new Date(2026, 0, 24, 15, 30, 5))).toBe("mosaic-log-20260124-153005.jsonl");
  });
});
