/**
 * The BrainFlow block's link to its board (app/blocks/devices/brainflow.ts): a Python sidecar
 * running native-bridges/python/mosaic_blocks/brainflow_board.py, polled by the block's own timer.
 * Each poll is one sidecar call that returns every sample the board delivered since the previous
 * one (at most `rows`; the rest stays queued in Python for the next poll) as a fixed-size result:
 * a header row, then the samples. This file holds the wire layout (the Python module's HEADER),
 * the load and the describe call, and the status text of the header's counts.
 */
import {
  BlockConfigError,
  type BlockContext,
  type PythonCallError,
  type PythonSidecar,
  type PythonSidecarState,
} from "../../engine";

/** The Python module and its functions. */
export const BRAINFLOW_MODULE = "mosaic_blocks.brainflow_board";

/** Commands (the call's one value), as in the Python module. */
export const CMD_DESCRIBE = 0;
export const CMD_POLL = 1;
export const CMD_STOP = 2;

/** Header row indices (brainflow_board.py, HEADER). */
export const H_N = 0;
export const H_STATE = 1;
export const H_LOST = 2;
export const H_RECONNECTS = 3;
export const H_FAILURES = 4;
export const H_RATE = 5;
export const H_CHANNELS = 6;
export const H_TOTAL = 7;

/** Board states (brainflow_board.py). */
export const enum BoardState {
  Idle = 0,
  Connecting = 1,
  Streaming = 2,
  Retrying = 3,
  Ended = 4,
  Stopped = 5,
  /** The session is prepared and streaming, no data yet. */
  Waiting = 6,
}

/** What a sidecar tells the link, routed by the block. */
export interface LinkHandlers {
  result(values: Float64Array): void;
  error(e: PythonCallError): void;
  status(state: PythonSidecarState, message?: string): void;
  output(line: string): void;
}

/** The loaded sidecar with the board's description. */
export interface BoardLink {
  sidecar: PythonSidecar;
  /** Rows and columns of one result ([1 + rows, width]). */
  rows: number;
  width: number;
  rate: number;
  channels: number;
  /** Channels of each selected kind, in the order of `Channels`. */
  kindCounts: number[];
}

/** Which param a load error points at. */
export function paramOfError(message: string): string {
  if (/master board/.test(message)) return "MasterBoard";
  if (/channel kind|has no \w+ channels/.test(message)) return "Channels";
  if (/playback file/.test(message)) return "File";
  return "Board";
}

/**
 * Starts the sidecar with the board module, then asks it (a describe call) for the board's rate
 * and channel count. Load errors (an unknown board, a missing file) are BlockConfigErrors naming
 * the param.
 */
export async function loadBoard(
  ctx: BlockContext,
  params: Record<string, unknown>,
  kinds: number,
  handlers: LinkHandlers,
): Promise<BoardLink> {
  const bridge = ctx.io.python!;
  let describe: ((v: Float64Array) => void) | undefined;
  let sidecar: PythonSidecar;
  try {
    sidecar = await bridge.load({
      module: BRAINFLOW_MODULE,
      function: "poll",
      init: "init",
      params,
      inputShape: { rows: 1, cols: 1 },
      cwd: ctx.resources.resolve("."),
      label: `block '${ctx.name}'`,
      // A poll only takes what the reader thread queued; a stop waits for the thread (≤ 5 s).
      hardLimitMs: 15_000,
      memoryLimitMb: 4096,
      onResult(_id, values) {
        if (describe) describe(values);
        else handlers.result(values);
      },
      onError: (_id, e) => handlers.error(e),
      onStatus: (s, m) => handlers.status(s, m),
      onOutput: (line) => handlers.output(line),
    });
  } catch (e) {
    const message = e instanceof Error ? e.message : String(e);
    const clean = message.replace(/^init raised ValueError: /, "").replace(/ \(at .*\)$/, "");
    throw new BlockConfigError(`BrainFlow: ${clean}`, paramOfError(clean));
  }
  const header = await new Promise<Float64Array>((resolve, reject) => {
    describe = (v) => resolve(v.slice(0, 2 * sidecar.outputShape.cols));
    if (sidecar.call(new Float64Array([CMD_DESCRIBE])) < 0) {
      reject(new BlockConfigError("BrainFlow: the Python sidecar did not accept a call"));
    }
  }).finally(() => {
    describe = undefined;
  });
  return {
    sidecar,
    rows: sidecar.outputShape.rows - 1,
    width: sidecar.outputShape.cols,
    rate: header[H_RATE]!,
    channels: header[H_CHANNELS]!,
    kindCounts: Array.from(
      header.subarray(sidecar.outputShape.cols, sidecar.outputShape.cols + kinds),
    ),
  };
}

/** The counts of the last header, for the status line and the counts action. */
export interface BoardCounts {
  state: number;
  lost: number;
  reconnects: number;
  failures: number;
  /** Samples the reader thread took from the board in this process. */
  total: number;
}

export function readCounts(header: Float64Array, into: BoardCounts): void {
  into.state = header[H_STATE]!;
  into.lost = header[H_LOST]!;
  into.reconnects = header[H_RECONNECTS]!;
  into.failures = header[H_FAILURES]!;
  into.total = header[H_TOTAL]!;
}

/** The board's state in a few words. */
export function stateText(c: BoardCounts, target: string, lastFailure: string): string {
  switch (c.state) {
    case BoardState.Connecting:
      return c.failures > 0
        ? `connecting to ${target} (attempt ${c.failures + 1})…`
        : `connecting to ${target}…`;
    case BoardState.Waiting:
      return c.failures > 0
        ? `waiting for data from ${target} (attempt ${c.failures + 1})…`
        : `waiting for data from ${target}…`;
    case BoardState.Streaming:
      return `streaming from ${target}`;
    case BoardState.Retrying:
      return `not streaming: ${lastFailure || "the board failed"}; retrying (attempt ${c.failures + 1})`;
    case BoardState.Ended:
      return `the playback file ended (${target})`;
    case BoardState.Stopped:
      return "stopped";
    default:
      return `${target}: not started`;
  }
}
