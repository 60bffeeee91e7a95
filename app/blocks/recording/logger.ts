import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  EMPTY_SHAPE,
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
    const seen = new Set<string>();
    for (const i of ctx.inputs) {
      if (seen.has(i.source)) {
        throw new BlockConfigError(
          `input '${i.source}' is listed twice; each input is written to its own file ` +
            `${i.source}.txt, so list it once`,
        );
      }
      seen.add(i.source);
    }
    const folder = /[\\/]$/.test(p.Folder) ? p.Folder : `${p.Folder}/`;
    const shapes: Shape[] = ctx.inputs.map((i) => i.shape ?? EMPTY_SHAPE);
    let channels: (LogChannel | null)[] = [];
    let opened = false;
    let noSink = false;
    let recording = p.Recording;
    let lines = 0;
    const throttle = new TextThrottle();
    const describe = () => {
      if (noSink) {
        ctx.setText("no log sink in this runtime: nothing is recorded");
        return;
      }
      const n = `${lines} line${lines === 1 ? "" : "s"} written to ${folder}`;
      ctx.setText(recording ? n : `stopped (${n})`);
    };
    const open = () => {
      if (opened) return;
      opened = true;
      channels = ctx.inputs.map((i) => ctx.openLog(folder, i.source, shapes[i.index]!));
      noSink = channels.some((c) => c === null);
      describe();
    };
    const setRecording = (on: boolean): string => {
      recording = on;
      describe();
      return on ? `recording to ${folder}` : `recording stopped (${lines} lines written)`;
    };
    return {
      start() {
        open();
      },
      process(f, port) {
        if (!recording || f.n === 0) return;
        const ch = channels[port];
        if (!ch) return;
        ch.write(f);
        lines += f.n;
        if (throttle.due(f.t[f.n - 1]!)) describe();
      },
      stop() {
        if (opened) describe();
      },
      setParam(name, value) {
        if (name === "Recording") setRecording(value as boolean);
      },
      actions: {
        start: {
          label: "Start recording",
          description: "Resume writing events to the log files",
          run: () => setRecording(true),
        },
        stop: {
          label: "Stop recording",
          description: "Pause writing (the files stay open)",
          run: () => setRecording(false),
        },
      },
    };
  },
});
