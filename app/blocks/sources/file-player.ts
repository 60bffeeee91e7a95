import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  errorMessage,
  LegacyParamsError,
  vectorShape,
  type BlockContext,
  type BlockInstance,
  type FileReadHandle,
  type Frame,
  type Resources,
} from "../../engine";
import { timerInput } from "../shared/inputs";
import { MAX_CHANNELS } from "../shared/limits";
import { index } from "../shared/params";
import { TextThrottle } from "../shared/text";
import { MAX_TIMER_HZ } from "../timing/scheduled-timer";
import {
  DelimitedStream,
  FILE_LIMITS,
  lastRowTime,
  parseDelimited,
  TIME_COLUMN_NAMES,
  type ParseOptions,
} from "./delimited-text";
import { recordingKind, recordingRows } from "./recording-rows";
import type { RowSource } from "./row-source";

const columnRef = () => z.union([z.string().min(1), index()]);
/** Most rows one wake-up of a self-timed player waits for (a batching interval rarely holds more). */
const MAX_BATCH_ROWS = 65536;

export const FilePlayer = defineBlock({
  type: "FilePlayer",
  category: "Sources",
  summary: "Plays a CSV/text recording: one row per timer tick, or at the recording's own timing.",
  help:
    "Reads and plays back a recording (paper Table 3), e.g. a CSV with a `time_s` column or a " +
    "log written by `Path`/Logger (then set `TimeColumn: 0`), or a lab recording: an XDF file " +
    "(one stream, `Stream`; its timestamps exactly as written, so a recording made by an " +
    "XdfRecorder replays with the stamps it was recorded with) or an EDF+/BDF+ file (signals of " +
    "one rate; times from each record's time-keeping annotation), read whole (up to 512 MiB; " +
    "Node hosts only), their channel names becoming the output's labels. A file up to 32 MiB is read and " +
    "checked whole when the pipeline loads; a bigger one is read in pieces as it plays (memory " +
    "stays small whatever its size), after its layout, first 1000 rows and last line were " +
    "checked at load, and a line that cannot be read later stops it with an error naming the " +
    "line (a browser reads recordings whole, up to 32 MiB). A line that cannot be read is " +
    "reported with its number and field; lines are at most 1 MiB, columns at most 65 536, and " +
    "what is not a regular file (a device, a pipe) is refused. " +
    "With a timer input it emits one row per tick, stamped with the tick's time (the pace and " +
    "desired rate are the timer's). Without an input it plays the rows at their original timing: " +
    "row i at start + (t_i − t_0)/Speed, stamped with that time; the rows due within one " +
    "batching interval (`BatchingMs`) go out together in one frame, as do all rows that are due " +
    "when the pipeline falls behind (rows are never skipped), and its desired rate is " +
    "Speed / (median row interval). At the end it starts again with `Loop: true` (the next " +
    "loop begins one median interval after the last row), otherwise it stops and reports that " +
    "it finished (a headless run ends when all its finite sources have). Empty lines and lines " +
    "starting with `#` are skipped; only the time column and the played columns must be " +
    "numbers (NaN and inf are accepted). `Speed` and `Loop` change while it plays. The " +
    "`position` output (for the panel's Player view; computed only while something reads it) " +
    "carries, for every row played and after a seek or a restart, [seconds from the first row, " +
    "the recording's duration in seconds (NaN without a time column), row number (1-based), " +
    "rows in the file (NaN while a big file is still being read)].",
  params: z.strictObject({
    File: z
      .string()
      .min(1)
      .describe(
        "The recording to play, relative to the pipeline file: CSV or other delimited text, " +
          "an XDF file (.xdf) or an EDF+/BDF+ file (.edf, .bdf)",
      ),
    Columns: z
      .array(columnRef())
      .min(1)
      .max(MAX_CHANNELS)
      .optional()
      .describe(
        "Columns to play, in output order: header names or 0-based indices (default: every " +
          "column except the time column); for XDF the stream's channels, for EDF+/BDF+ the " +
          "signals (labels or indices), all of one rate",
      ),
    TimeColumn: z
      .union([columnRef(), z.literal(false)])
      .optional()
      .describe(
        `The column holding each row's time in seconds: a header name or 0-based index, or false ` +
          `for none (default: a header named ${TIME_COLUMN_NAMES.join(", ")}; case-insensitive)`,
      ),
    Header: z
      .union([z.literal("auto"), z.boolean()])
      .default("auto")
      .describe(
        "Whether the first line holds column names; auto: yes when one of its fields is not a number",
      ),
    Delimiter: z
      .enum(["auto", ",", ";", "\t", " "])
      .default("auto")
      .describe(
        "Field separator; auto picks tab, comma, semicolon or spaces from the first line " +
          "(' ' means any run of spaces or tabs)",
      ),
    Stream: z
      .union([z.string().min(1), index()])
      .optional()
      .describe(
        "XDF recordings: the stream to play, by name or 0-based index (default: the first " +
          "numeric stream)",
      ),
    Loop: z.boolean().default(false).describe("Start again from the first row at the end"),
    Speed: z
      .number()
      .positive()
      .default(1)
      .describe(
        "Playback speed factor for original timing (2 plays twice as fast); unused with a timer input",
      ),
  }),
  live: ["Speed", "Loop"],
  legacyParams(args) {
    const path = args[0]?.trim() ?? "";
    if (args.length !== 1 || path === "") {
      throw new LegacyParamsError(
        `expected one argument (the file path), got ${args.length}`,
        "File",
      );
    }
    return { File: path };
  },
  legacyForm: "[path]: the file to play",
  inputs: { min: 0, max: 1, labels: ["timer"] },
  outputs: ["out", "position"],
  finite: (p) => !p.Loop,
  views: ["player", "scope"],
  panel:
    "Player: a seek bar with the position and the duration, restart, pause and resume, speed " +
    "and loop; a scope of the played columns.",
  async create(ctx, p) {
    const timed = ctx.inputs.length === 1;
    if (timed) timerInput(ctx, 0);
    const src = await loadRows(ctx.resources, p, !timed);
    try {
      return play(ctx, p, timed, src);
    } catch (e) {
      src.close();
      throw e;
    }
  },
});

interface Params {
  File: string;
  Columns?: (string | number)[] | undefined;
  Stream?: string | number | undefined;
  TimeColumn?: string | number | false | undefined;
  Header: "auto" | boolean;
  Delimiter: "auto" | "," | ";" | "\t" | " ";
  Loop: boolean;
  Speed: number;
}

/** Seconds for messages: at most 3 decimals. */
const fmtSeconds = (x: number): string => String(Math.round(x * 1000) / 1000);

const disorderText = (line: number, file: string, t: number, prev: number): string =>
  `line ${line} of '${file}': time ${t} is before the previous row's ${prev}; original ` +
  "timing needs non-decreasing times";

function wholeRows(text: string, o: ParseOptions): RowSource {
  const t = parseDelimited(text, o);
  const c = t.columns.length;
  return {
    whole: true,
    width: c,
    ...(t.hasHeader ? { labels: t.columns.map((k) => t.names[k]!) } : {}),
    hasTimes: t.times !== null,
    total: t.rows,
    fill: (upTo) => Math.min(upTo, t.rows),
    time: (r) => t.times![r]!,
    line: (r) => t.lines[r]!,
    copy(r, into, at) {
      for (let k = 0; k < c; k++) into[at + k] = t.values[r * c + k]!;
    },
    release() {},
    rewind() {},
    lastTime: () => t.times![t.rows - 1]!,
    error: undefined,
    close() {},
  };
}

/**
 * A big file's rows, read as they play. With `ordered` (original timing), a row whose time is
 * before the previous one ends the rows there.
 */
function streamedRows(h: FileReadHandle, o: ParseOptions, ordered: boolean): RowSource {
  const s = new DelimitedStream(h, o);
  let checked = 0;
  let prev = -Infinity;
  let disorder: string | undefined;
  let total: number | undefined;
  return {
    whole: false,
    width: s.layout.columns.length,
    hasTimes: s.layout.timeColumn >= 0,
    get total() {
      return total;
    },
    fill(upTo) {
      let n = s.fill(upTo);
      if (ordered) {
        for (; checked < n && disorder === undefined; checked++) {
          const t = s.time(checked);
          if (!(t >= prev)) {
            disorder = disorderText(s.line(checked), o.file, t, prev);
            break;
          }
          prev = t;
        }
        if (disorder !== undefined) n = Math.min(n, checked);
      }
      if (s.ended && s.error === undefined && disorder === undefined) total = s.known;
      return n;
    },
    time: (r) => s.time(r),
    line: (r) => s.line(r),
    copy: (r, into, at) => s.copy(r, into, at),
    release: (r) => s.release(r),
    rewind() {
      s.rewind();
      checked = 0;
      prev = -Infinity;
    },
    lastTime: () => lastRowTime(h, h.size, s.layout, o),
    get error() {
      return disorder ?? s.error?.message;
    },
    close: () => h.close(),
  };
}

/** Reads a whole (small) file through its handle. */
function readWhole(h: FileReadHandle): string {
  const buf = new Uint8Array(h.size);
  let got = 0;
  while (got < buf.length) {
    const n = h.read(buf.subarray(got), got);
    if (n === 0) break;
    got += n;
  }
  const decoder = new (
    globalThis as unknown as {
      TextDecoder: new () => { decode(b: Uint8Array): string };
    }
  ).TextDecoder();
  return decoder.decode(buf.subarray(0, got));
}

/**
 * Opens the recording: streamed when the host reads in pieces (Node) and the file is bigger than
 * FILE_LIMITS.wholeBytes, else read whole (and a text bigger than that refused).
 */
async function loadRows(res: Resources, p: Params, ordered: boolean): Promise<RowSource> {
  const where = (): string => {
    try {
      return res.resolve(p.File);
    } catch {
      return p.File;
    }
  };
  const o: ParseOptions = {
    file: p.File,
    header: p.Header,
    delimiter: p.Delimiter,
    columns: p.Columns,
    timeColumn: p.TimeColumn,
  };
  let h: FileReadHandle | undefined;
  try {
    h = res.openRead?.(p.File);
  } catch (e) {
    throw new BlockConfigError(`cannot read '${where()}': ${errorMessage(e)}`, "File");
  }
  if (h && Number.isNaN(h.size)) {
    throw new BlockConfigError(
      `'${h.path}' is not a regular file (a device or a pipe): a FilePlayer plays recordings ` +
        "saved as files",
      "File",
    );
  }
  const kind = recordingKind(p.File);
  if (kind) return openRecording(h, kind, p);
  if (h && h.size > FILE_LIMITS.wholeBytes) {
    try {
      return streamedRows(h, o, ordered);
    } catch (e) {
      h.close();
      throw e;
    }
  }
  let text: string;
  try {
    text = h ? readWhole(h) : await res.readText(p.File);
  } catch (e) {
    throw new BlockConfigError(`cannot read '${where()}': ${errorMessage(e)}`, "File");
  } finally {
    h?.close();
  }
  if (text.length > FILE_LIMITS.wholeBytes) {
    throw new BlockConfigError(
      `'${p.File}' has ${text.length} characters; here a recording is read whole, at most ` +
        `${FILE_LIMITS.wholeBytes} (mosaic run and the desktop app play bigger files as they read ` +
        "them)",
      "File",
    );
  }
  return wholeRows(text, o);
}

/** An XDF or EDF+/BDF+ recording, read whole (Node hosts; a browser cannot read them yet). */
function openRecording(h: FileReadHandle | undefined, kind: "xdf" | "edf", p: Params): RowSource {
  if (!h) {
    throw new BlockConfigError(
      `'${p.File}' is ${kind === "xdf" ? "an XDF" : "an EDF+/BDF+"} recording: this runtime cannot read binary files (play it with mosaic run, mosaic serve or the desktop app)`,
      "File",
    );
  }
  try {
    return recordingRows(h, kind, {
      file: p.File,
      stream: p.Stream,
      columns: p.Columns,
    });
  } finally {
    h.close();
  }
}

/** The load-time checks of original timing and the player itself. */
function play(ctx: BlockContext, p: Params, timed: boolean, src: RowSource): BlockInstance {
  const c = src.width;
  // The first rows must be readable when the pipeline loads (all of a whole file).
  const first = src.fill(src.total ?? FILE_LIMITS.firstRows);
  if (src.error !== undefined && first < FILE_LIMITS.firstRows) {
    throw new BlockConfigError(src.error, "File");
  }
  if (first === 0) throw new BlockConfigError(`'${p.File}' has a header but no data rows`, "File");
  let span = 0;
  let t0 = 0;
  let median = NaN;
  if (!timed) {
    if (!src.hasTimes) {
      throw new BlockConfigError(
        `'${p.File}' has no time column, so it cannot be played at its original timing; either ` +
          "give the FilePlayer a timer input (one row per tick) or name the time column with " +
          "TimeColumn",
        "TimeColumn",
      );
    }
    if (first < 2) {
      throw new BlockConfigError(
        `'${p.File}' has only one row; original timing needs at least two rows (or a timer input)`,
        "File",
      );
    }
    // The rows checked at load (all of a whole file) give the median interval.
    const dts = new Float64Array(first - 1);
    for (let i = 1; i < first; i++) {
      const dt = src.time(i) - src.time(i - 1);
      if (!(dt >= 0)) {
        throw new BlockConfigError(
          disorderText(src.line(i), p.File, src.time(i), src.time(i - 1)),
          "TimeColumn",
        );
      }
      dts[i - 1] = dt;
    }
    dts.sort();
    const m = dts.length;
    median = m % 2 === 1 ? dts[(m - 1) / 2]! : (dts[m / 2 - 1]! + dts[m / 2]!) / 2;
    if (!(median > 0)) {
      throw new BlockConfigError(
        `the median interval between rows of '${p.File}' is 0 (repeated times); original ` +
          "timing needs increasing times",
        "TimeColumn",
      );
    }
    const rowHz = p.Speed / median;
    const tooFast = speedProblem(p.Speed, median, p.File);
    if (tooFast !== undefined)
      throw new BlockConfigError(tooFast, p.Speed !== 1 ? "Speed" : "File");
    t0 = src.time(0);
    // Only a loop needs the last row (read from the file's end when it streams).
    if (p.Loop) span = src.lastTime() - t0 + median;
    if (ctx.declaredRate === undefined) ctx.setDesiredRate(rowHz);
  }
  let speed = p.Speed;
  let loop = p.Loop;
  const out = ctx.output(vectorShape(c), undefined, {
    ...(src.labels ? { labels: src.labels } : {}),
    ...(src.unit ? { unit: src.unit } : {}),
  });
  const position = playPosition(ctx, src);

  let row = 0;
  let loops = 0;
  let done = false;
  let paused = false;
  let started = false;
  let base = NaN;
  let pausedAt = NaN;
  let stoppedAt = NaN;
  /** Why playing stopped early: a bad line met in a streamed file. */
  let failed: string | undefined;
  const throttle = new TextThrottle();
  const has = (r: number): boolean => src.fill(r + 1) > r;

  const describe = () => {
    const total = src.total !== undefined ? ` / ${src.total}` : "";
    if (failed !== undefined) ctx.setText(`stopped at row ${row}: ${failed}`);
    else if (done) ctx.setText(`finished: ${src.total ?? row} rows played`);
    else
      ctx.setText(
        `${paused ? "paused at " : ""}row ${row}${total}${loops > 0 ? ` (loop ${loops + 1})` : ""}`,
      );
  };
  const finish = () => {
    done = true;
    if (src.error !== undefined && failed === undefined) {
      failed = src.error;
      ctx.error(`stopped playing: ${failed}`);
    }
    describe();
    ctx.finish();
  };
  /** Advances past the row just played; returns false when playback ended. */
  const advance = (): boolean => {
    row++;
    if (has(row)) return true;
    if (src.error !== undefined) return false;
    if (loop) {
      src.rewind();
      row = 0;
      loops++;
      return has(0);
    }
    return false;
  };
  const dueTime = (r: number, l: number): number => base + (src.time(r) - t0 + l * span) / speed;
  /** The row after `r` of pass `l` in a scan ahead, or undefined where the scan stops. */
  const after = (r: number, l: number): [number, number] | undefined => {
    if (has(r + 1)) return [r + 1, l];
    // A streamed file's next pass is read after this one: scans stop at its end.
    if (!loop || !src.whole) return undefined;
    return [0, l + 1];
  };
  /**
   * When the worker must wake at the latest: the due time of the last row within the batching
   * interval of the next one (rows then go out together, as a device sends packets; DESIGN.md
   * §3). From the next row's due time on, the rows due go out whenever the worker is awake
   * anyway, in the same steps as timer ticks of the same times (so a replay meets the other
   * inputs of a block as the recorded run did).
   */
  const nextWake = (): number => {
    const first = dueTime(row, loops);
    const batch = ctx.batching;
    if (!(batch > 0)) return first;
    let last = first;
    let at: [number, number] | undefined = [row, loops];
    for (let k = 0; k < MAX_BATCH_ROWS; k++) {
      at = after(at[0], at[1]);
      if (!at) break;
      const d = dueTime(at[0], at[1]);
      if (d > first + batch) break;
      last = d;
    }
    return last;
  };

  const arm = (): void => ctx.at(dueTime(row, loops), onTime, nextWake());

  const onTime = (): void => {
    if (paused || done) return;
    const t = ctx.now();
    for (;;) {
      // Count the rows due by now, then emit them in one frame stamped with their own times.
      let n = 0;
      let at: [number, number] | undefined = [row, loops];
      while (at && dueTime(at[0], at[1]) <= t) {
        n++;
        at = after(at[0], at[1]);
      }
      let ended = false;
      if (n > 0) {
        const o = out.frame(n);
        const ov = o.v;
        const po = position.frame(n);
        for (let e = 0; e < n; e++) {
          o.t[e] = dueTime(row, loops);
          src.copy(row, ov, e * c);
          if (po) position.put(po, e, o.t[e]!, row);
          if (!advance()) {
            ended = true;
            o.n = e + 1;
            break;
          }
        }
        src.release(row);
        out.emit(o);
        if (po) position.emit(po, o.n);
      }
      if (ended) {
        finish();
        return;
      }
      // A streamed file's next pass (Loop) begins after this frame: its due rows go in the next.
      if (n > 0 && !src.whole && row === 0 && dueTime(0, loops) <= t) continue;
      break;
    }
    if (throttle.due(t)) describe();
    arm();
  };

  const schedule = () => {
    if (timed || paused || done || !started) return;
    arm();
  };
  /** The first row at or after `s` seconds from the first row (rows are in time order). */
  const rowAt = (s: number): number | undefined => {
    const total = src.total ?? 0;
    const want = src.time(0) + s;
    let lo = 0;
    let hi = total;
    while (lo < hi) {
      const mid = (lo + hi) >> 1;
      if (src.time(mid) < want) lo = mid + 1;
      else hi = mid;
    }
    return lo < total ? lo : undefined;
  };

  /** The `seek` action: play on from the row at `arg` seconds (whole files, timed by their rows). */
  const seek = (arg: unknown): string => {
    const s = typeof arg === "string" ? Number(arg) : arg;
    if (typeof s !== "number" || !Number.isFinite(s) || s < 0) {
      return "seek: give the seconds from the recording's first row, e.g. 12.5";
    }
    if (!src.whole || !src.hasTimes) {
      return src.hasTimes
        ? `seek needs a recording read whole (text up to ${FILE_LIMITS.wholeBytes} bytes, XDF or EDF+)`
        : "seek needs a time column";
    }
    const r = rowAt(s);
    if (r === undefined) {
      return `the recording lasts ${fmtSeconds(src.lastTime() - src.time(0))} s: nothing at ${s} s`;
    }
    row = r;
    done = false;
    if (!timed && started) base = ctx.now() - (src.time(r) - t0 + loops * span) / speed;
    describe();
    schedule();
    position.now(row);
    return `at ${fmtSeconds(src.time(r) - src.time(0))} s (row ${r + 1})`;
  };

  const rewind = () => {
    if (row !== 0 || loops !== 0 || done) src.rewind();
    row = 0;
    loops = 0;
    done = false;
    failed = undefined;
    throttle.reset();
    if (!timed && started) base = ctx.now();
    describe();
    schedule();
    position.now(row);
  };

  /** Speed while playing: the position stays where it is, the rows after it come faster. */
  const setSpeed = (v: number): void => {
    if (!timed) {
      const problem = speedProblem(v, median, p.File);
      if (problem !== undefined) throw new Error(problem);
      const anchor = paused ? pausedAt : started ? ctx.now() : stoppedAt;
      if (!Number.isNaN(base) && !Number.isNaN(anchor)) {
        base = anchor - ((anchor - base) * speed) / v;
      }
      // The rate it is judged by follows (unless the file declares one).
      if (ctx.declaredRate === undefined) ctx.setDesiredRate(v / median);
    }
    speed = v;
    schedule();
  };
  /** Loop while playing: the end of the file starts it again (or, turned off, ends it). */
  const setLoop = (v: boolean): void => {
    if (v && !timed && span === 0) span = src.lastTime() - t0 + median;
    loop = v;
    if (!v) schedule();
  };
  describe();

  return {
    start() {
      started = true;
      if (!timed) {
        // The first start plays from the pipeline start; after a stop, the remaining rows
        // move by the time it was stopped (as after pause/resume), so none bursts out late.
        if (Number.isNaN(base)) base = ctx.startTime;
        else if (!paused && !Number.isNaN(stoppedAt)) base += ctx.now() - stoppedAt;
      }
      schedule();
    },
    stop() {
      started = false;
      stoppedAt = ctx.now();
    },
    process(f) {
      if (paused || done) return;
      const want = f.n;
      if (want === 0) return;
      const n = loop ? want : Math.min(want, src.fill(row + want) - row);
      if (n <= 0) {
        finish();
        return;
      }
      const o = out.frame(n);
      const ov = o.v;
      const ft = f.t;
      const po = position.frame(n);
      let ended = false;
      for (let e = 0; e < n; e++) {
        o.t[e] = ft[e]!;
        src.copy(row, ov, e * c);
        if (po) position.put(po, e, ft[e]!, row);
        if (!advance()) {
          ended = true;
          o.n = e + 1;
          break;
        }
      }
      src.release(row);
      out.emit(o);
      if (po) position.emit(po, o.n);
      if (ended) finish();
      else if (throttle.due(ft[o.n - 1]!)) describe();
    },
    reset() {
      paused = false;
      rewind();
    },
    dispose() {
      src.close();
    },
    setParam(name, value) {
      if (name === "Speed") setSpeed(value as number);
      else if (name === "Loop") setLoop(value as boolean);
    },
    actions: {
      restart: {
        label: "Restart",
        description: "Play again from the first row",
        run() {
          paused = false;
          rewind();
          return `restarted ${p.File}`;
        },
      },
      pause: {
        label: "Pause",
        description: "Stop emitting rows until resumed",
        run() {
          if (paused || done) return done ? "already finished" : "already paused";
          paused = true;
          pausedAt = ctx.now();
          describe();
          return `paused at row ${row}`;
        },
      },
      seek: {
        label: "Seek",
        description: "Jump to a time: seconds from the recording's first row (argument)",
        run: (arg?: unknown) => seek(arg),
      },
      resume: {
        label: "Resume",
        description: "Continue from the row where it paused",
        run() {
          if (!paused) return "not paused";
          paused = false;
          if (!timed && !Number.isNaN(base)) base += ctx.now() - pausedAt;
          describe();
          schedule();
          return `resumed at row ${row}`;
        },
      },
    },
  };
}

/** Why `speed` cannot play rows `median` seconds apart (faster than the engine paces), or undefined. */
function speedProblem(speed: number, median: number, file: string): string | undefined {
  const rowHz = speed / median;
  if (!(rowHz > MAX_TIMER_HZ)) return undefined;
  const fileHz = Number((1 / median).toPrecision(6));
  return speed !== 1
    ? `at Speed ${speed} the rows of '${file}' (${fileHz} Hz) would play at ` +
        `${Number(rowHz.toPrecision(6))} Hz, above the fastest the engine paces, ` +
        `${MAX_TIMER_HZ} Hz: lower Speed`
    : `the rows of '${file}' come at ${fileHz} Hz, above the fastest the engine paces, ` +
        `${MAX_TIMER_HZ} Hz: play it with a timer input (one row per tick) or resample it`;
}

/** Row of a played recording, for the `position` output: seconds, duration, row, rows. */
interface PlayPosition {
  /** A frame for `n` positions, or null when nothing reads the output. */
  frame(n: number): Frame | null;
  put(f: Frame, e: number, t: number, row: number): void;
  emit(f: Frame, n: number): void;
  /** Emits the position of `row` (the next to play) now: after a seek or a restart. */
  now(row: number): void;
}

function playPosition(ctx: BlockContext, src: RowSource): PlayPosition {
  const port = ctx.output(vectorShape(4), "position", {
    labels: ["seconds", "duration", "row", "rows"],
  });
  const first = src.hasTimes ? src.time(0) : NaN;
  let duration = NaN;
  if (src.hasTimes) {
    try {
      duration = src.lastTime() - first;
    } catch {
      // A streamed file whose end cannot be read yet: the duration stays unknown.
    }
  }
  const put = (f: Frame, e: number, t: number, row: number): void => {
    f.t[e] = t;
    const v = f.v;
    v[e * 4] = src.hasTimes ? src.time(row) - first : NaN;
    v[e * 4 + 1] = duration;
    v[e * 4 + 2] = row + 1;
    v[e * 4 + 3] = src.total ?? NaN;
  };
  return {
    frame: (n) => (port.idle ? null : port.frame(n)),
    put,
    emit(f, n) {
      f.n = n;
      port.emit(f);
    },
    now(row) {
      if (port.idle || !(src.fill(row + 1) > row)) return;
      const f = port.frame(1);
      put(f, 0, ctx.now(), row);
      port.emit(f);
    },
  };
}
