/**
 * How FilePlayer reads rows, whatever the file: delimited text (delimited-text.ts) or a lab
 * recording (recording-rows.ts). The rows of a recording as the player reads them: all in memory (a file up to
 * FILE_LIMITS.wholeBytes, checked whole at load), or streamed from the file as they play. Row
 * indices count from the first data row of the current pass.
 */
export interface RowSource {
  /** Every row is in memory: a scan may look past the end into the next pass (Loop). */
  readonly whole: boolean;
  /** Values per row. */
  readonly width: number;
  /** A name per value (header names, XDF channel labels, EDF signal labels), when known. */
  readonly labels?: readonly string[];
  /** The unit of every value, when the file says. */
  readonly unit?: string;
  readonly hasTimes: boolean;
  /** Rows in a pass, once known (from the start for a whole file). */
  readonly total: number | undefined;
  /** Makes rows [0, upTo) readable where they exist; returns min(upTo, rows available). */
  fill(upTo: number): number;
  time(r: number): number;
  line(r: number): number;
  copy(r: number, into: Float64Array, at: number): void;
  /** Rows before `r` are not needed any more. */
  release(r: number): void;
  /** The next pass, from the first row. */
  rewind(): void;
  /** The time of the file's last row. */
  lastTime(): number;
  /** Why the rows end before the file does (a bad line met while playing). */
  readonly error: string | undefined;
  close(): void;
}
