/**
 * Parses a delimited text recording (CSV, TSV, semicolon- or space-separated; MOSAIC's own log
 * format) into typed arrays for the FilePlayer. Errors are BlockConfigErrors naming the line,
 * the field and the param to fix.
 */
import { BlockConfigError, closest } from "../../engine";

export type Delimiter = "auto" | "," | ";" | "\t" | " ";
export type ColumnRef = string | number;

export interface ParseOptions {
  /** The file name as written, for messages. */
  file: string;
  header: "auto" | boolean;
  delimiter: Delimiter;
  /** Data columns; undefined = every column but the time column. */
  columns: readonly ColumnRef[] | undefined;
  /** undefined = auto (a header named like a time column), false = none. */
  timeColumn: ColumnRef | false | undefined;
}

export interface ParsedTable {
  /** Header names, or "0", "1", … without a header. */
  names: string[];
  hasHeader: boolean;
  delimiter: Exclude<Delimiter, "auto">;
  /** Indices (0-based) of the data columns, in output order. */
  columns: number[];
  /** Index of the time column, -1 for none. */
  timeColumn: number;
  rows: number;
  /** rows × columns.length values, row-major. */
  values: Float64Array;
  /** One time per row (seconds), or null without a time column. */
  times: Float64Array | null;
  /** 1-based file line of every row (for messages). */
  lines: Int32Array;
}

/** Header names recognised as the time column (case-insensitive). */
export const TIME_COLUMN_NAMES = ["time", "time_s", "t", "timestamp", "seconds"] as const;

const NUMBER_RE = /^[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?$/;
const NAN_RE = /^[+-]?nan$/i;
const INF_RE = /^([+-]?)inf(?:inity)?$/i;

/** The number a field holds (NaN and ±inf as written by loggers included), or undefined. */
export function parseField(s: string): number | undefined {
  if (NUMBER_RE.test(s)) return Number(s);
  if (NAN_RE.test(s)) return NaN;
  const m = INF_RE.exec(s);
  if (m) return m[1] === "-" ? -Infinity : Infinity;
  return undefined;
}

function split(line: string, d: Exclude<Delimiter, "auto">): string[] {
  if (d === " ") return line.trim().split(/[ \t]+/);
  return line.split(d).map((f) => f.trim());
}

function detectDelimiter(line: string): Exclude<Delimiter, "auto"> {
  if (line.includes("\t")) return "\t";
  if (line.includes(",")) return ",";
  if (line.includes(";")) return ";";
  return " ";
}

const isSkipped = (line: string): boolean => {
  const t = line.trim();
  return t === "" || t.startsWith("#");
};

/** A short, escaped excerpt of the file for messages (control characters as \u escapes). */
const quote = (s: string): string => JSON.stringify(s.length > 30 ? s.slice(0, 30) + "…" : s);
/** The header's names for messages: a few excerpts (the first line may be anything at all). */
const listNames = (names: readonly string[]): string =>
  names.length <= 8
    ? names.map(quote).join(", ")
    : `${names.slice(0, 8).map(quote).join(", ")}, … (${names.length} in all)`;

export function parseDelimited(text: string, o: ParseOptions): ParsedTable {
  const all = text.split(/\r?\n/);
  let first = 0;
  while (first < all.length && isSkipped(all[first]!)) first++;
  if (first >= all.length) {
    throw new BlockConfigError(`file '${o.file}' is empty (no data lines)`, "File");
  }
  const firstLine = all[first]!.replace(/^\uFEFF/, "");
  const delimiter = o.delimiter === "auto" ? detectDelimiter(firstLine) : o.delimiter;
  const firstFields = split(firstLine, delimiter);
  const width = firstFields.length;
  const looksLikeHeader = firstFields.some((f) => parseField(f) === undefined);
  const hasHeader = o.header === "auto" ? looksLikeHeader : o.header;
  const names = hasHeader ? firstFields : firstFields.map((_, i) => String(i));

  const resolve = (ref: ColumnRef, param: string): number => {
    if (typeof ref === "number") {
      if (ref >= width) {
        throw new BlockConfigError(
          `column index ${ref} is out of range: '${o.file}' has ${width} column${width === 1 ? "" : "s"} ` +
            `(valid: 0–${width - 1})`,
          param,
        );
      }
      return ref;
    }
    if (!hasHeader) {
      throw new BlockConfigError(
        `column '${ref}' is a name, but '${o.file}' has no header line; give 0-based column indices ` +
          `(0–${width - 1}) or set Header: true`,
        param,
      );
    }
    let i = names.indexOf(ref);
    if (i < 0) i = names.findIndex((n) => n.toLowerCase() === ref.toLowerCase());
    if (i < 0) {
      const s = closest(ref, names);
      throw new BlockConfigError(
        `'${o.file}' has no column '${ref}' (its columns: ${listNames(names)})` +
          (s !== undefined ? `; did you mean ${quote(s)}?` : ""),
        param,
      );
    }
    return i;
  };

  let timeColumn = -1;
  if (o.timeColumn === undefined) {
    if (hasHeader) {
      timeColumn = names.findIndex((n) =>
        (TIME_COLUMN_NAMES as readonly string[]).includes(n.toLowerCase()),
      );
    }
  } else if (o.timeColumn !== false) {
    timeColumn = resolve(o.timeColumn, "TimeColumn");
  }
  const columns =
    o.columns !== undefined
      ? o.columns.map((c) => resolve(c, "Columns"))
      : names.map((_, i) => i).filter((i) => i !== timeColumn);
  if (columns.length === 0) {
    throw new BlockConfigError(
      `'${o.file}' has no data columns besides its time column ${quote(names[timeColumn]!)}`,
      "Columns",
    );
  }

  // Count the data rows, then fill.
  const start = hasHeader ? first + 1 : first;
  let rows = 0;
  for (let i = start; i < all.length; i++) if (!isSkipped(all[i]!)) rows++;
  if (rows === 0) {
    throw new BlockConfigError(`'${o.file}' has a header but no data rows`, "File");
  }
  const c = columns.length;
  const values = new Float64Array(rows * c);
  const times = timeColumn >= 0 ? new Float64Array(rows) : null;
  const lines = new Int32Array(rows);
  let r = 0;
  for (let i = start; i < all.length; i++) {
    const line = all[i]!;
    if (isSkipped(line)) continue;
    const fields = split(line, delimiter);
    const lineNo = i + 1;
    if (fields.length !== width) {
      throw new BlockConfigError(
        `line ${lineNo} of '${o.file}' has ${fields.length} field${fields.length === 1 ? "" : "s"}; ` +
          `expected ${width} like line ${first + 1} (delimiter ${quote(delimiter)})`,
        "File",
      );
    }
    const read = (col: number): number => {
      const v = parseField(fields[col]!);
      if (v === undefined) {
        throw new BlockConfigError(
          `line ${lineNo} of '${o.file}': field ${col + 1} (column ${quote(names[col]!)}) is ` +
            `${quote(fields[col]!)}, which is not a number`,
          "File",
        );
      }
      return v;
    };
    for (let k = 0; k < c; k++) values[r * c + k] = read(columns[k]!);
    if (times) times[r] = read(timeColumn);
    lines[r] = lineNo;
    r++;
  }
  return { names, hasHeader, delimiter, columns, timeColumn, rows, values, times, lines };
}
