/**
 * FilePlayer: plays a recording. The block's definition; the player is in file-player-*.ts:
 * -rows (reading the file's rows), -timing (the load-time checks of original timing), -run (the
 * player: pacing, seek, speed, loop), -position, -status, -seek and -instance (its actions).
 */
import { z } from "zod";
import { defineBlock, LegacyParamsError } from "../../engine";
import { timerInput } from "../shared/inputs";
import { MAX_CHANNELS } from "../shared/limits";
import { index } from "../shared/params";
import { TIME_COLUMN_NAMES } from "./delimited-text";
import { playerInstance } from "./file-player-instance";
import { loadRows } from "./file-player-rows";
import { PlayerRun } from "./file-player-run";
import { loadTiming } from "./file-player-timing";

const columnRef = () => z.union([z.string().min(1), index()]);

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
      const timing = loadTiming(ctx, p, timed, src);
      return playerInstance(new PlayerRun(ctx, p, timed, src, timing));
    } catch (e) {
      src.close();
      throw e;
    }
  },
});
