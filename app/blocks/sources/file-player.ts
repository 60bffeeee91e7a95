import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  errorMessage,
  LegacyParamsError,
  vectorShape,
} from "../../engine";
import { timerInput } from "../shared/inputs";
import { index } from "../shared/params";
import { TextThrottle } from "../shared/text";
import { MAX_TIMER_HZ } from "../timing/scheduled-timer";
import { parseDelimited, TIME_COLUMN_NAMES } from "./delimited-text";
import { MAX_CHANNELS } from "../shared/limits";

const columnRef = () => z.union([z.string().min(1), index()]);
/** Most rows one wake-up of a self-timed player waits for (a batching interval rarely holds more). */
const MAX_BATCH_ROWS = 65536;

export const FilePlayer = defineBlock({
  type: "FilePlayer",
  category: "Sources",
  summary: "Plays a CSV/text recording: one row per timer tick, or at the recording's own timing.",
  help:
    "Reads and plays back a recording (paper Table 3), e.g. a CSV with a `time_s` column or a " +
    "log written by `Path`/Logger (then set `TimeColumn: 0`). The whole file is read and checked " +
    "when the pipeline loads; a line that cannot be read is reported with its number and field. " +
    "With a timer input it emits one row per tick, stamped with the tick's time (the pace and " +
    "desired rate are the timer's). Without an input it plays the rows at their original timing: " +
    "row i at start + (t_i − t_0)/Speed, stamped with that time; the rows due within one " +
    "batching interval (`BatchingMs`) go out together in one frame, as do all rows that are due " +
    "when the pipeline falls behind (rows are never skipped), and its desired rate is " +
    "Speed / (median row interval). At the end it starts again with `Loop: true` (the next " +
    "loop begins one median interval after the last row), otherwise it stops and reports that " +
    "it finished (a headless run ends when all its finite sources have). Empty lines and lines " +
    "starting with `#` are skipped; only the time column and the played columns must be " +
    "numbers (NaN and inf are accepted).",
  params: z.strictObject({
    File: z
      .string()
      .min(1)
      .describe(
        "The recording to play, relative to the pipeline file (CSV or other delimited text)",
      ),
    Columns: z
      .array(columnRef())
      .min(1)
      .max(MAX_CHANNELS)
      .optional()
      .describe(
        "Columns to play, in output order: header names or 0-based indices (default: every " +
          "column except the time column)",
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
    Loop: z.boolean().default(false).describe("Start again from the first row at the end"),
    Speed: z
      .number()
      .positive()
      .default(1)
      .describe(
        "Playback speed factor for original timing (2 plays twice as fast); unused with a timer input",
      ),
  }),
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
  finite: (p) => !p.Loop,
  views: ["scope"],
  panel: "Scope of the played columns, the row position, and restart/pause/resume buttons.",
  async create(ctx, p) {
    const timed = ctx.inputs.length === 1;
    if (timed) timerInput(ctx, 0);
    let text: string;
    try {
      text = await ctx.resources.readText(p.File);
    } catch (e) {
      let where = p.File;
      try {
        where = ctx.resources.resolve(p.File);
      } catch {
        // keep the name as written
      }
      throw new BlockConfigError(`cannot read '${where}': ${errorMessage(e)}`, "File");
    }
    const table = parseDelimited(text, {
      file: p.File,
      header: p.Header,
      delimiter: p.Delimiter,
      columns: p.Columns,
      timeColumn: p.TimeColumn,
    });
    const rows = table.rows;
    const c = table.columns.length;
    const values = table.values;
    const times = table.times;
    let span = 0;
    if (!timed) {
      if (!times) {
        throw new BlockConfigError(
          `'${p.File}' has no time column, so it cannot be played at its original timing; either ` +
            "give the FilePlayer a timer input (one row per tick) or name the time column with " +
            "TimeColumn",
          "TimeColumn",
        );
      }
      if (rows < 2) {
        throw new BlockConfigError(
          `'${p.File}' has only one row; original timing needs at least two rows (or a timer input)`,
          "File",
        );
      }
      const dts = new Float64Array(rows - 1);
      for (let i = 1; i < rows; i++) {
        const dt = times[i]! - times[i - 1]!;
        if (!(dt >= 0)) {
          throw new BlockConfigError(
            `line ${table.lines[i]} of '${p.File}': time ${times[i]} is before the previous row's ` +
              `${times[i - 1]}; original timing needs non-decreasing times`,
            "TimeColumn",
          );
        }
        dts[i - 1] = dt;
      }
      dts.sort();
      const m = dts.length;
      const median = m % 2 === 1 ? dts[(m - 1) / 2]! : (dts[m / 2 - 1]! + dts[m / 2]!) / 2;
      if (!(median > 0)) {
        throw new BlockConfigError(
          `the median interval between rows of '${p.File}' is 0 (repeated times); original ` +
            "timing needs increasing times",
          "TimeColumn",
        );
      }
      const rowHz = p.Speed / median;
      if (rowHz > MAX_TIMER_HZ) {
        const fileHz = Number((1 / median).toPrecision(6));
        throw new BlockConfigError(
          p.Speed !== 1
            ? `at Speed ${p.Speed} the rows of '${p.File}' (${fileHz} Hz) would play at ` +
                `${Number(rowHz.toPrecision(6))} Hz, above the fastest the engine paces, ` +
                `${MAX_TIMER_HZ} Hz: lower Speed`
            : `the rows of '${p.File}' come at ${fileHz} Hz, above the fastest the engine paces, ` +
                `${MAX_TIMER_HZ} Hz: play it with a timer input (one row per tick) or resample it`,
          p.Speed !== 1 ? "Speed" : "File",
        );
      }
      span = times[rows - 1]! - times[0]! + median;
      if (ctx.declaredRate === undefined) ctx.setDesiredRate(p.Speed / median);
    }
    const t0 = times ? times[0]! : 0;
    const speed = p.Speed;
    const loop = p.Loop;
    const out = ctx.output(vectorShape(c));

    let row = 0;
    let loops = 0;
    let done = false;
    let paused = false;
    let started = false;
    let base = NaN;
    let pausedAt = NaN;
    let stoppedAt = NaN;
    const throttle = new TextThrottle();

    const describe = () => {
      if (done) ctx.setText(`finished: ${rows} rows played`);
      else
        ctx.setText(
          `${paused ? "paused at " : ""}row ${row} / ${rows}${loops > 0 ? ` (loop ${loops + 1})` : ""}`,
        );
    };
    const finish = () => {
      done = true;
      describe();
      ctx.finish();
    };
    /** Advances past the row just played; returns false when playback ended. */
    const advance = (): boolean => {
      row++;
      if (row < rows) return true;
      if (loop) {
        row = 0;
        loops++;
        return true;
      }
      return false;
    };
    const dueTime = (r: number, l: number): number => base + (times![r]! - t0 + l * span) / speed;
    /**
     * When to wake next: the due time of the last row within the batching interval of the next
     * one (rows then go out together, as a device sends packets; DESIGN.md §3).
     */
    const nextWake = (): number => {
      const first = dueTime(row, loops);
      const batch = ctx.batching;
      if (!(batch > 0)) return first;
      let last = first;
      let r = row;
      let l = loops;
      for (let k = 0; k < MAX_BATCH_ROWS; k++) {
        r++;
        if (r >= rows) {
          if (!loop) break;
          r = 0;
          l++;
        }
        const d = dueTime(r, l);
        if (d > first + batch) break;
        last = d;
      }
      return last;
    };

    const onTime = (t: number): void => {
      if (paused || done) return;
      // Count the rows due by now, then emit them in one frame stamped with their own times.
      let n = 0;
      let r = row;
      let l = loops;
      while (dueTime(r, l) <= t) {
        n++;
        r++;
        if (r >= rows) {
          if (!loop) break;
          r = 0;
          l++;
        }
      }
      let ended = false;
      if (n > 0) {
        const o = out.frame(n);
        const ov = o.v;
        for (let e = 0; e < n; e++) {
          o.t[e] = dueTime(row, loops);
          const src = row * c;
          const dst = e * c;
          for (let k = 0; k < c; k++) ov[dst + k] = values[src + k]!;
          if (!advance()) ended = true;
        }
        out.emit(o);
      }
      if (ended) {
        finish();
        return;
      }
      if (throttle.due(t)) describe();
      ctx.at(nextWake(), onTime);
    };

    const schedule = () => {
      if (timed || paused || done || !started) return;
      ctx.at(nextWake(), onTime);
    };
    const rewind = () => {
      row = 0;
      loops = 0;
      done = false;
      throttle.reset();
      if (!timed && started) base = ctx.now();
      describe();
      schedule();
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
        const n = loop ? want : Math.min(want, rows - row);
        const o = out.frame(n);
        const ov = o.v;
        const ft = f.t;
        let ended = false;
        for (let e = 0; e < n; e++) {
          o.t[e] = ft[e]!;
          const src = row * c;
          const dst = e * c;
          for (let k = 0; k < c; k++) ov[dst + k] = values[src + k]!;
          if (!advance()) ended = true;
        }
        out.emit(o);
        if (ended) finish();
        else if (throttle.due(ft[n - 1]!)) describe();
      },
      reset() {
        paused = false;
        rewind();
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
  },
});
