/**
 * Parses a delimited text recording (CSV, TSV, semicolon- or space-separated; MOSAIC's own log
 * format) into typed arrays for the FilePlayer: a whole text at once (`parseDelimited`), or a
 * file of any size in pieces as it is played (`DelimitedStream`, which keeps only the rows not
 * yet played). Errors are BlockConfigErrors naming the line, the field and the param to fix.
 * What a file may hold is bounded (FILE_LIMITS): the longest line, the most columns, and the
 * size read whole.
 */
import { BlockConfigError, closest } from "../../engine";
import { MAX_CHANNELS } from "../shared/limits";

/** UTF-8 decoding: TextDecoder exists wherever the engine runs (Node, browsers, workers). */
interface Utf8Decoder {
  decode(bytes?: Uint8Array, options?: { stream?: boolean }): string;
}
const newDecoder = (): Utf8Decoder =>
  new (globalThis as unknown as { TextDecoder: new () => Utf8Decoder }).TextDecoder();

/**
 * Bounds on recordings (issue 14, item 12). A field object so that tests can lower them.
 * - `wholeBytes`: files up to this size are read and checked whole when the pipeline loads;
 *   bigger ones are read in `chunkBytes` pieces as they play (where the host can: Node), after
 *   the layout, the first `firstRows` rows and the last line were checked at load. A host that
 *   can only read whole texts (a browser) refuses bigger ones.
 * - `lineChars`: the longest line (a binary file has no line ends).
 * - `columns`: the most fields in a line.
 */
export const FILE_LIMITS = {
  wholeBytes: 32 * 1024 * 1024,
  chunkBytes: 64 * 1024,
  firstRows: 1000,
  lineChars: 1024 * 1024,
  columns: MAX_CHANNELS,
};

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

/** How a recording is laid out: what its first line (header or first row) says. */
export interface Layout {
  names: string[];
  hasHeader: boolean;
  delimiter: Exclude<Delimiter, "auto">;
  /** Indices (0-based) of the data columns, in output order. */
  columns: number[];
  /** Index of the time column, -1 for none. */
  timeColumn: number;
  /** Fields in every line. */
  width: number;
  /** 1-based line number of the first line. */
  firstLine: number;
}

/** Reads the layout from the file's first (non-skipped) line. */
export function readLayout(line: string, lineNo: number, o: ParseOptions): Layout {
  const firstLine = line.replace(/^\uFEFF/, "");
  const delimiter = o.delimiter === "auto" ? detectDelimiter(firstLine) : o.delimiter;
  const firstFields = split(firstLine, delimiter);
  const width = firstFields.length;
  checkWidth(width, lineNo, o);
  const looksLikeHeader = firstFields.some((f) => parseField(f) === undefined);
  const hasHeader = o.header === "auto" ? looksLikeHeader : o.header;
  const names = hasHeader ? firstFields : firstFields.map((_, i) => String(i));
  const head: Head = { names, hasHeader, width };
  const timeColumn = timeColumnOf(head, o);
  const columns = dataColumns(head, timeColumn, o);
  return { names, hasHeader, delimiter, columns, timeColumn, width, firstLine: lineNo };
}

/** What the first line says before the columns are chosen. */
type Head = Pick<Layout, "names" | "hasHeader" | "width">;

/** A first line of more fields than a recording may have columns is refused. */
function checkWidth(width: number, lineNo: number, o: ParseOptions): void {
  if (width > FILE_LIMITS.columns) {
    throw new BlockConfigError(
      `line ${lineNo} of '${o.file}' has ${width} fields; a recording may have at most ` +
        `${FILE_LIMITS.columns} columns`,
      "File",
    );
  }
}

/** The time column: the one given, else (no `TimeColumn`) a header named like one; -1 for none. */
function timeColumnOf(head: Head, o: ParseOptions): number {
  if (o.timeColumn === undefined) {
    if (!head.hasHeader) return -1;
    return head.names.findIndex((n) =>
      (TIME_COLUMN_NAMES as readonly string[]).includes(n.toLowerCase()),
    );
  }
  if (o.timeColumn === false) return -1;
  return resolveColumn(o.timeColumn, "TimeColumn", head, o);
}

/** The data columns: those given, else every column but the time column; at least one. */
function dataColumns(head: Head, timeColumn: number, o: ParseOptions): number[] {
  const columns =
    o.columns !== undefined
      ? o.columns.map((c) => resolveColumn(c, "Columns", head, o))
      : head.names.map((_, i) => i).filter((i) => i !== timeColumn);
  if (columns.length === 0) {
    throw new BlockConfigError(
      `'${o.file}' has no data columns besides its time column ${quote(head.names[timeColumn]!)}`,
      "Columns",
    );
  }
  return columns;
}

/** The index of the column `ref` (a 0-based index, or a header name) given in `param`. */
function resolveColumn(ref: ColumnRef, param: string, head: Head, o: ParseOptions): number {
  const { names, hasHeader, width } = head;
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
  return columnNamed(ref, param, names, o);
}

/** The index of the header name `ref` (exact, else ignoring case); suggests the closest if none. */
function columnNamed(ref: string, param: string, names: string[], o: ParseOptions): number {
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
}

/**
 * Parses one data line: its values into `values` from `at`, its time into `times[row]` (when the
 * layout has a time column). Throws a BlockConfigError naming the line and the field.
 */
export function parseRow(
  line: string,
  lineNo: number,
  L: Layout,
  o: ParseOptions,
  values: Float64Array,
  at: number,
  times: Float64Array | null,
  row: number,
): void {
  const { names, delimiter, width, columns, timeColumn } = L;
  const fields = split(line, delimiter);
  if (fields.length !== width) {
    throw new BlockConfigError(
      `line ${lineNo} of '${o.file}' has ${fields.length} field${fields.length === 1 ? "" : "s"}; ` +
        `expected ${width} like line ${L.firstLine} (delimiter ${quote(delimiter)})`,
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
  const c = columns.length;
  for (let k = 0; k < c; k++) values[at + k] = read(columns[k]!);
  if (times && timeColumn >= 0) times[row] = read(timeColumn);
}

export function parseDelimited(text: string, o: ParseOptions): ParsedTable {
  const all = text.split(/\r?\n/);
  let first = 0;
  while (first < all.length && isSkipped(all[first]!)) first++;
  if (first >= all.length) {
    throw new BlockConfigError(`file '${o.file}' is empty (no data lines)`, "File");
  }
  const L = readLayout(all[first]!, first + 1, o);
  const { names, hasHeader, delimiter, columns, timeColumn } = L;

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
    parseRow(line, i + 1, L, o, values, r * c, times, r);
    lines[r] = i + 1;
    r++;
  }
  return { names, hasHeader, delimiter, columns, timeColumn, rows, values, times, lines };
}

/** Where a stream reads its bytes: `read` fills `into` from byte `position`, 0 at the end. */
export interface ByteSource {
  read(into: Uint8Array, position: number): number;
}

/**
 * A recording read in pieces as it is played. The layout (header, columns) is read when it is
 * made; rows are parsed on demand (`fill`) and kept until `release`d, so memory stays bounded by
 * what is not yet played, whatever the file's size. Row indices count from the first data row
 * of the current pass; `rewind` starts the next pass (Loop) from the top of the file. A line that
 * cannot be read ends the rows there: `error` says which and why (its rows before stay readable).
 */
export class DelimitedStream {
  layout!: Layout;
  /** The first bad line met, if any (no rows after it). */
  error: BlockConfigError | undefined;
  /** The file's end was reached in this pass (rows known: `known`). */
  ended = false;

  private readonly chunk: Uint8Array;
  private decoder = newDecoder();
  private pos = 0;
  private eof = false;
  private text = "";
  private at = 0;
  private lineNo = 0;
  /** A first line that is data (no header), parsed before the rest. */
  private pendingFirst: string | undefined;

  private readonly width: number;
  private cap = 256;
  private times: Float64Array;
  private values: Float64Array;
  private lines: Int32Array;
  /** Row index of buffer slot 0, and how many rows are buffered. */
  private base = 0;
  private count = 0;
  /** Rows before this index may be dropped. */
  private keepFrom = 0;

  constructor(
    private readonly src: ByteSource,
    private readonly o: ParseOptions,
  ) {
    this.chunk = new Uint8Array(FILE_LIMITS.chunkBytes);
    this.start();
    this.width = this.layout.columns.length;
    this.times = new Float64Array(this.cap);
    this.values = new Float64Array(this.cap * this.width);
    this.lines = new Int32Array(this.cap);
  }

  /** Rows of this pass read so far (the file has at least this many). */
  get known(): number {
    return this.base + this.count;
  }

  /** Makes rows [0, upTo) readable where the file has them; returns min(upTo, rows available). */
  fill(upTo: number): number {
    while (this.base + this.count < upTo && !this.ended && this.error === undefined) {
      let line: string | undefined;
      let lineNo: number;
      if (this.pendingFirst !== undefined) {
        line = this.pendingFirst;
        this.pendingFirst = undefined;
        lineNo = this.layout.firstLine;
      } else {
        try {
          line = this.nextLine();
        } catch (e) {
          this.error = e as BlockConfigError;
          break;
        }
        lineNo = this.lineNo;
        if (line === undefined) {
          this.ended = true;
          break;
        }
        if (isSkipped(line)) continue;
      }
      this.room();
      const slot = this.count;
      try {
        parseRow(
          line,
          lineNo,
          this.layout,
          this.o,
          this.values,
          slot * this.width,
          this.times,
          slot,
        );
      } catch (e) {
        this.error = e as BlockConfigError;
        break;
      }
      this.lines[slot] = lineNo;
      this.count++;
    }
    return Math.min(upTo, this.base + this.count);
  }

  time(r: number): number {
    return this.times[r - this.base]!;
  }

  /** 1-based file line of row `r`. */
  line(r: number): number {
    return this.lines[r - this.base]!;
  }

  /** Copies row `r`'s values into `into` from `at`. */
  copy(r: number, into: Float64Array, at: number): void {
    const w = this.width;
    const from = (r - this.base) * w;
    for (let k = 0; k < w; k++) into[at + k] = this.values[from + k]!;
  }

  /** Rows before `r` are not needed any more. */
  release(r: number): void {
    if (r > this.keepFrom) this.keepFrom = r;
  }

  /** Starts the next pass from the file's first data row. */
  rewind(): void {
    this.start();
    this.base = 0;
    this.count = 0;
    this.keepFrom = 0;
    this.ended = false;
    this.error = undefined;
  }

  /** Room for one more row: drops released rows first, grows only when all are needed. */
  private room(): void {
    if (this.count < this.cap) return;
    const drop = Math.min(this.keepFrom - this.base, this.count);
    const w = this.width;
    if (drop > 0) {
      this.times.copyWithin(0, drop, this.count);
      this.lines.copyWithin(0, drop, this.count);
      this.values.copyWithin(0, drop * w, this.count * w);
      this.base += drop;
      this.count -= drop;
    }
    if (this.count < this.cap) return;
    this.cap *= 2;
    const t = new Float64Array(this.cap);
    t.set(this.times);
    this.times = t;
    const l = new Int32Array(this.cap);
    l.set(this.lines);
    this.lines = l;
    const v = new Float64Array(this.cap * w);
    v.set(this.values);
    this.values = v;
  }

  /** Reads from the top: the layout from the first line that is not skipped. */
  private start(): void {
    this.decoder = newDecoder();
    this.pos = 0;
    this.eof = false;
    this.text = "";
    this.at = 0;
    this.lineNo = 0;
    this.pendingFirst = undefined;
    for (;;) {
      const line = this.nextLine();
      if (line === undefined) {
        throw new BlockConfigError(`file '${this.o.file}' is empty (no data lines)`, "File");
      }
      if (isSkipped(line)) continue;
      this.layout = readLayout(line, this.lineNo, this.o);
      if (!this.layout.hasHeader) this.pendingFirst = line;
      return;
    }
  }

  /** The next line (without its line end), or undefined at the end of the file. */
  private nextLine(): string | undefined {
    for (;;) {
      const nl = this.text.indexOf("\n", this.at);
      if (nl >= 0) {
        let end = nl;
        if (end > this.at && this.text.charCodeAt(end - 1) === 13) end--;
        const line = this.text.slice(this.at, end);
        this.at = nl + 1;
        this.lineNo++;
        return line;
      }
      if (this.text.length - this.at > FILE_LIMITS.lineChars) {
        throw new BlockConfigError(
          `line ${this.lineNo + 1} of '${this.o.file}' is longer than ${FILE_LIMITS.lineChars} ` +
            "characters: is it a text recording?",
          "File",
        );
      }
      if (this.eof) {
        if (this.at >= this.text.length) return undefined;
        const line = this.text.slice(this.at).replace(/\r$/, "");
        this.at = this.text.length;
        this.lineNo++;
        return line;
      }
      const n = this.src.read(this.chunk, this.pos);
      this.pos += n;
      const rest = this.text.slice(this.at);
      this.at = 0;
      if (n === 0) {
        this.eof = true;
        this.text = rest + this.decoder.decode();
      } else {
        this.text = rest + this.decoder.decode(this.chunk.subarray(0, n), { stream: true });
      }
    }
  }
}

/**
 * The last row of a file read from its end (a streamed recording's last time, for Loop): its
 * time, or a BlockConfigError when the last line cannot be read.
 */
export function lastRowTime(src: ByteSource, size: number, L: Layout, o: ParseOptions): number {
  const bytes = Math.min(size, Math.max(64 * 1024, 4 * L.width * 32));
  const buf = new Uint8Array(bytes);
  let got = 0;
  while (got < bytes) {
    const n = src.read(buf.subarray(got), size - bytes + got);
    if (n === 0) break;
    got += n;
  }
  const lines = newDecoder().decode(buf.subarray(0, got)).split(/\r?\n/);
  for (let i = lines.length - 1; i > 0; i--) {
    const line = lines[i]!;
    if (isSkipped(line)) continue;
    const values = new Float64Array(L.columns.length);
    const times = new Float64Array(1);
    const fields = split(line, L.delimiter);
    if (fields.length !== L.width) {
      throw new BlockConfigError(
        `the last line of '${o.file}' has ${fields.length} field${fields.length === 1 ? "" : "s"}; ` +
          `expected ${L.width} like line ${L.firstLine} (delimiter ${quote(L.delimiter)})`,
        "File",
      );
    }
    parseRow(line, 0, L, o, values, 0, times, 0);
    return times[0]!;
  }
  throw new BlockConfigError(
    `the last line of '${o.file}' is longer than ${bytes} bytes: is it a text recording?`,
    "File",
  );
}
