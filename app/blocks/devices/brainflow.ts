import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  vectorShape,
  type BlockContext,
  type BlockInstance,
} from "../../engine";
import { BrainFlowRun } from "./brainflow-run";

const boardName = z.union([z.string().trim().min(1).max(64), z.number().int().min(-100).max(999)]);

export const CHANNEL_KINDS = [
  "exg",
  "emg",
  "eeg",
  "ecg",
  "eog",
  "accel",
  "gyro",
  "magnetometer",
  "package",
  "timestamp",
] as const;

const params = z.strictObject({
  Board: boardName.describe(
    "BrainFlow's board id: its name as in BoardIds (SYNTHETIC_BOARD, CYTON_BOARD, GANGLION_BOARD, " +
      "GFORCE_PRO_BOARD, CALLIBRI_EMG_BOARD, PLAYBACK_FILE_BOARD, MINDROVE_WIFI_BOARD…; case and " +
      "the _BOARD ending may be left out: synthetic, cyton, playback) or its number",
  ),
  Library: z
    .enum(["auto", "brainflow", "mindrove"])
    .default("auto")
    .describe(
      "Which BoardShim: brainflow, or mindrove (Mindrove's fork, its own board ids); auto: " +
        "mindrove for names beginning with MINDROVE, else brainflow",
    ),
  Channels: z
    .array(z.enum(CHANNEL_KINDS))
    .min(1)
    .max(8)
    .refine((a) => new Set(a).size === a.length, "a kind is listed twice")
    .default(["exg"])
    .describe(
      "Which of the board's channels go out, by kind, in this order (BoardShim.get_exg_channels, " +
        "get_accel_channels, get_gyro_channels…); exg: all EMG/EEG/ECG/EOG channels; package: the " +
        "board's package number (get_package_num_channel), to check for gaps; timestamp: BrainFlow's " +
        "time of arrival (get_timestamp_channel, UNIX s)",
    ),
  SerialPort: z
    .string()
    .max(256)
    .optional()
    .describe("BrainFlowInputParams.serial_port (Cyton, Ganglion dongle: /dev/ttyUSB0, COM3)"),
  MacAddress: z.string().max(64).optional().describe("BrainFlowInputParams.mac_address"),
  IpAddress: z.string().max(256).optional().describe("BrainFlowInputParams.ip_address"),
  IpPort: z.number().int().min(0).max(65535).optional().describe("BrainFlowInputParams.ip_port"),
  IpProtocol: z
    .number()
    .int()
    .min(0)
    .max(2)
    .optional()
    .describe("BrainFlowInputParams.ip_protocol (0 none, 1 UDP, 2 TCP)"),
  SerialNumber: z.string().max(256).optional().describe("BrainFlowInputParams.serial_number"),
  OtherInfo: z.string().max(1024).optional().describe("BrainFlowInputParams.other_info"),
  Timeout: z
    .number()
    .int()
    .min(0)
    .max(600)
    .optional()
    .describe("BrainFlowInputParams.timeout, s (Bluetooth discovery)"),
  File: z
    .string()
    .min(1)
    .max(4096)
    .optional()
    .describe(
      "BrainFlowInputParams.file: the recording the playback board plays (relative to the pipeline's folder)",
    ),
  MasterBoard: boardName
    .optional()
    .describe(
      "BrainFlowInputParams.master_board: the board that recorded what the playback (or streaming) board plays",
    ),
  Simulated: z
    .boolean()
    .default(false)
    .describe(
      "Read BrainFlow's synthetic board instead of the board, in the board's channels and at its rate " +
        "(what --simulate-devices sets): no device is opened",
    ),
  PollRate: z
    .number()
    .min(1)
    .max(1000)
    .default(50)
    .describe(
      "Hz: how often the block asks the sidecar for what the board delivered (latency ≤ one poll period plus a call)",
    ),
  Silence: z
    .number()
    .min(0)
    .max(3600)
    .default(3)
    .describe(
      "Seconds without data after which a streaming board counts as lost and is prepared again (the playback board: the file has ended); 0: never",
    ),
  Retry: z
    .number()
    .min(0)
    .max(60)
    .default(0)
    .describe(
      "Seconds between attempts after a failure; 0: 0.5 s doubling to 5 s (BrainFlow's release_session, prepare_session)",
    ),
  LogLevel: z
    .number()
    .int()
    .min(0)
    .max(6)
    .default(6)
    .describe(
      "BrainFlow's own logger (BoardShim.set_log_level: 0 trace … 4 error … 6 off); its lines show as warnings",
    ),
});

type Params = z.output<typeof params>;

/** The Python module's params (JSON) for these block params. */
function moduleParams(ctx: BlockContext, p: Params): Record<string, unknown> {
  const input: Record<string, unknown> = {};
  const put = (key: string, v: unknown): void => {
    if (v !== undefined) input[key] = v;
  };
  put("serial_port", p.SerialPort);
  put("mac_address", p.MacAddress);
  put("ip_address", p.IpAddress);
  put("ip_port", p.IpPort);
  put("ip_protocol", p.IpProtocol);
  put("serial_number", p.SerialNumber);
  put("other_info", p.OtherInfo);
  put("timeout", p.Timeout);
  put("file", p.File !== undefined ? resolveFile(ctx, p.File) : undefined);
  return {
    board: p.Board,
    library: p.Library,
    channels: p.Channels,
    input,
    ...(p.MasterBoard !== undefined ? { master_board: p.MasterBoard } : {}),
    poll_rate: p.PollRate,
    simulated: p.Simulated,
    silence: p.Silence,
    retry: p.Retry,
    log_level: p.LogLevel,
  };
}

/** The playback file's full path (a confined host refuses one outside its folders). */
function resolveFile(ctx: BlockContext, file: string): string {
  try {
    return ctx.resources.resolve(file);
  } catch (e) {
    throw new BlockConfigError(e instanceof Error ? e.message : String(e), "File");
  }
}

/** "CYTON_BOARD on /dev/ttyUSB0", for messages. */
function targetOf(p: Params): string {
  if (p.Simulated) return `BrainFlow's synthetic board as ${String(p.Board)}`;
  const where = p.SerialPort ?? p.IpAddress ?? p.MacAddress ?? p.File;
  return `board ${String(p.Board)}${where ? ` (${where})` : ""}`;
}

/** The playback board (the same id in brainflow and mindrove) plays a file to its end. */
const isPlayback = (board: string | number): boolean =>
  board === -3 || /^playback(_file(_board)?)?$/i.test(String(board).trim());

/** Without Python (the browser build): the block loads, says so and emits nothing. */
function withoutPython(ctx: BlockContext): BlockInstance {
  ctx.output(vectorShape(1), "data");
  const text =
    "BrainFlow needs Python (not available in the browser build): run the pipeline with mosaic run or the desktop app";
  ctx.setText(text);
  return {
    start() {
      ctx.setText(text);
      ctx.warn(text);
    },
  };
}

export const BrainFlow = defineBlock({
  type: "BrainFlow",
  category: "Devices",
  summary:
    "Any board BrainFlow (or Mindrove's fork) reads — Mindrove, gForce, Callibri EMG, OpenBCI, the synthetic and playback boards — at its native rate, through the Python sidecar.",
  help:
    "An acquisition board through BrainFlow's BoardShim (https://brainflow.readthedocs.io), in " +
    "the Python sidecar (the `brainflow` and `mindrove` packages of native-bridges/python, " +
    "which ship their native libraries): `Board` names the board (BoardIds), the other params " +
    "are its BrainFlowInputParams (serial port, address, MAC, file of the playback board…). " +
    "`Library: mindrove` (or a board name beginning with MINDROVE) uses Mindrove's fork, whose " +
    "BoardShim has its own ids (MINDROVE_WIFI_BOARD). The output is one vector per sample of " +
    "the `Channels` kinds (default the board's EXG channels, BoardShim.get_exg_channels; " +
    "accel, gyro… optional) at the board's own rate (BoardShim.get_sampling_rate), which " +
    "becomes the block's desired rate. **Design:** in the sidecar a reader thread prepares the " +
    "session, starts the stream and takes everything BrainFlow holds every 10 ms " +
    "(get_board_data, which removes what it returns, so no sample is read twice; never " +
    "get_current_board_data) into a queue; the block has no input and polls the sidecar at " +
    "`PollRate` (its own timer, default 50 Hz): each poll is one call whose fixed-size result " +
    "carries a header (count, state, lost samples, reconnections) and up to a bound of queued " +
    "samples (the rest come with the next poll), emitted at once as one frame, stamped on the " +
    "board's sample clock (the first batch's last sample at its arrival, then 1 / rate apart). " +
    "So every sample goes out exactly once, at most one poll period plus a call after it " +
    "reached the computer. Lost samples are the gaps in the board's package-number channel. " +
    "A failure (prepare_session or start_stream raising, no data for `Silence` s) releases the " +
    "session and prepares it again after 0.5 s, doubling to 5 s; the first failure of each " +
    "kind is an error that says what to check (a port that cannot be opened, a board that does " +
    "not answer), later ones are counted in the status. An unknown board is an error at load " +
    "with a “did you mean”. A killed or crashed sidecar is reported and restarted (the board " +
    "prepared again; samples it held are lost). No simulator is needed: BrainFlow's synthetic " +
    "board (SYNTHETIC_BOARD) and playback board (PLAYBACK_FILE_BOARD with `File` and " +
    "`MasterBoard`, which plays a file written by DataFilter.write_file) are the simulators, " +
    "and `--simulate-devices` sets `Simulated`: the synthetic board's signals (its 16 EXG " +
    "channels cycled over the board's, accel, gyro) linearly interpolated from its 250 Hz to " +
    "the board's channels and rate, so the pipeline keeps its shapes and rates; a playback " +
    "that reaches the end of its file finishes the run. The board runs in real time even " +
    "under the virtual clock (each poll is waited for, but a fast virtual run gets few samples: a " +
    "warning says so). Tested here on the synthetic and " +
    "playback boards only. Needs `mosaic run`, `mosaic serve` or the desktop app (the browser " +
    "build has no Python: the status says so). Protocol notes in docs/protocols.md.",
  params,
  inputs: { min: 0, max: 0 },
  outputs: ["data"],
  finite: (p) => isPlayback(p.Board) && !p.Simulated,
  eventLoop: true,
  views: ["scope", "spider"],
  panel:
    "Scope of the channels; the board's state, samples, lost samples, reconnections, sidecar restarts.",
  async create(ctx, p) {
    if (!ctx.io.python) return withoutPython(ctx);
    const run = new BrainFlowRun(ctx, {
      target: targetOf(p),
      playback: isPlayback(p.Board) && !p.Simulated,
      pollRate: p.PollRate,
      kinds: p.Channels,
    });
    await run.load(moduleParams(ctx, p));
    return run.instance();
  },
});
