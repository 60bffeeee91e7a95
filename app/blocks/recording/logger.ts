import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  EMPTY_SHAPE,
  type BlockContext,
  type BlockInstance,
  type Frame,
  type InputInfo,
  type LogChannel,
  type Shape,
} from "../../engine";
import { TextThrottle } from "../shared/text";

export const Logger = defineBlock({
  type: "Logger",
  category: "Recording",
  summary: "Writes every event of each input to `<Folder>/<input>.txt`, one text line per event.",
  help:
    "Flexible data logging (paper III-I, Table 3): each input's events go to their own file, " +
    "`<Folder>/<input>.txt` (`<Folder>/<Block>.<port>.txt` for a named port), in the same line " +
    "format as a block's `Path`: `timestamp,v1,…,vn` with the UNIX timestamp in seconds with " +
    "microseconds and the values in shortest round-trip form (a matrix value is written row by " +
    "row; a timer input writes its tick times). Writes are buffered off the hot path by the " +
    "host. The `stop` action (or `Recording: false`) pauses writing and `start` resumes it; the " +
    "files are opened when the pipeline starts. Where the runtime has no log sink (a browser " +
    "page without downloads) it records nothing and says so in its status.",
  params: z.strictObject({
    Folder: z
      .string()
      .min(1)
      .default("recordings/")
      .describe(
        "Folder of the log files, relative to the pipeline file; each input is written to " +
          "<Folder>/<input block name>.txt",
      ),
    Recording: z
      .boolean()
      .default(true)
      .describe("Write events; false pauses the recording (can be changed while running)"),
  }),
  inputs: { min: 1, max: Infinity },
  outputs: [],
  live: ["Recording"],
  views: ["label"],
  panel: "Lines written per input, the folder, and start/stop buttons.",
  create(ctx, p) {
    checkDistinct(ctx.inputs);
    const folder = /[\\/]$/.test(p.Folder) ? p.Folder : `${p.Folder}/`;
    return new LoggerRun(ctx, folder, p.Recording).instance();
  },
});

/** Each input is written to the file named after it, so no input may be listed twice. */
function checkDistinct(inputs: readonly InputInfo[]): void {
  const seen = new Set<string>();
  for (const i of inputs) {
    if (seen.has(i.source)) {
      throw new BlockConfigError(
        `input '${i.source}' is listed twice; each input is written to its own file ` +
          `${i.source}.txt, so list it once`,
      );
    }
    seen.add(i.source);
  }
}

/** One Logger at run time: its log files, whether it records, and the lines written. */
class LoggerRun {
  private readonly shapes: Shape[];
  /** Per input, its log file (null where the runtime has no log sink); opened at start. */
  private channels: (LogChannel | null)[] = [];
  private opened = false;
  private noSink = false;
  private lines = 0;
  private readonly throttle = new TextThrottle();

  constructor(
    private readonly ctx: BlockContext,
    /** The folder of the log files, ending in a separator. */
    private readonly folder: string,
    private recording: boolean,
  ) {
    this.shapes = ctx.inputs.map((i) => i.shape ?? EMPTY_SHAPE);
  }

  /** The block instance the engine drives, with its start and stop actions. */
  instance(): BlockInstance {
    return {
      start: () => this.open(),
      process: this.process,
      stop: () => {
        if (this.opened) this.describe();
      },
      setParam: (name, value) => {
        if (name === "Recording") this.setRecording(value as boolean);
      },
      actions: {
        start: {
          label: "Start recording",
          description: "Resume writing events to the log files",
          run: () => this.setRecording(true),
        },
        stop: {
          label: "Stop recording",
          description: "Pause writing (the files stay open)",
          run: () => this.setRecording(false),
        },
      },
    };
  }

  /** Writes a frame to its input's file while recording (bound: the instance's `process`). */
  private readonly process = (f: Frame, port: number): void => {
    if (!this.recording || f.n === 0) return;
    const ch = this.channels[port];
    if (!ch) return;
    ch.write(f);
    this.lines += f.n;
    if (this.throttle.due(f.t[f.n - 1]!)) this.describe();
  };

  /** Opens one log file per input (once). */
  private open(): void {
    if (this.opened) return;
    this.opened = true;
    this.channels = this.ctx.inputs.map((i) =>
      this.ctx.openLog(this.folder, i.source, this.shapes[i.index]!),
    );
    this.noSink = this.channels.some((c) => c === null);
    this.describe();
  }

  /** Starts or pauses the recording; says which. */
  private setRecording(on: boolean): string {
    this.recording = on;
    this.describe();
    return on ? `recording to ${this.folder}` : `recording stopped (${this.lines} lines written)`;
  }

  /** The status: lines written and where, whether stopped, or that nothing can be recorded. */
  private describe(): void {
    if (this.noSink) {
      this.ctx.setText("no log sink in this runtime: nothing is recorded");
      return;
    }
    const n = `${this.lines} line${this.lines === 1 ? "" : "s"} written to ${this.folder}`;
    this.ctx.setText(this.recording ? n : `stopped (${n})`);
  }
}
