/**
 * Helpers every loader stage shares: the diagnostics collector (positions from node ranges) and
 * the words a message uses to describe what the file holds.
 */
import { isMap, isScalar, isSeq, type LineCounter, type Node as YamlNode } from "yaml";
import type { Diagnostic } from "../diagnostics";
import type { SourcePos } from "./spec";

/** Collects the diagnostics of one file; positions come from node ranges and the line counter. */
export class Collector {
  readonly list: Diagnostic[] = [];
  private errorCount = 0;
  constructor(
    readonly file: string,
    readonly lc: LineCounter,
  ) {}

  /** 1-based line and column of a node's start ({0, 0} when it has no range). */
  pos(node: YamlNode | null | undefined): SourcePos {
    const r = node?.range;
    if (!r) return { line: 0, col: 0 };
    return this.at(r[0]);
  }

  /** 1-based line and column of an offset into the source. */
  at(offset: number): SourcePos {
    const p = this.lc.linePos(offset);
    return { line: p.line, col: p.col };
  }

  /** Adds a diagnostic and returns it (a later stage may complete a warning's message). */
  add(
    severity: Diagnostic["severity"],
    code: string,
    at: SourcePos,
    message: string,
    extra: Partial<Diagnostic> = {},
  ): Diagnostic {
    const d: Diagnostic = {
      severity,
      code,
      message,
      file: this.file,
      line: at.line,
      col: at.col,
      ...extra,
    };
    this.list.push(d);
    if (severity === "error") this.errorCount++;
    return d;
  }

  error(code: string, at: SourcePos, message: string, extra: Partial<Diagnostic> = {}): void {
    this.add("error", code, at, message, extra);
  }

  warn(code: string, at: SourcePos, message: string, extra: Partial<Diagnostic> = {}): Diagnostic {
    return this.add("warning", code, at, message, extra);
  }

  /** Errors so far (counted as they come: stages ask after every block). */
  get errors(): number {
    return this.errorCount;
  }
}

/** A scalar's value as a string (numbers and booleans as JS prints them, null as ""). */
export function scalarString(node: unknown): string | undefined {
  if (isScalar(node)) {
    const v = node.value;
    if (typeof v === "string") return v;
    if (typeof v === "number" || typeof v === "boolean") return String(v);
    if (v === null) return "";
  }
  return undefined;
}

export function describeValue(v: unknown): string {
  if (v === null || v === undefined) return "nothing";
  if (Array.isArray(v)) return "a list";
  if (typeof v === "object") return "a mapping";
  if (typeof v === "string")
    return `the string ${JSON.stringify(v.length > 40 ? v.slice(0, 40) + "…" : v)}`;
  return `${typeof v} ${String(v)}`;
}

export function describeNode(node: unknown): string {
  if (isMap(node)) return "a mapping";
  if (isSeq(node)) return "a list";
  if (isScalar(node)) return describeValue(node.value);
  return "nothing";
}

/** True for a missing value: no node, or a null scalar (`Key:` or `Key: ~`). */
export function isNullish(node: unknown): boolean {
  return node === undefined || node === null || (isScalar(node) && node.value === null);
}
