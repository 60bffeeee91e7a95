/**
 * The one UI↔engine protocol (DESIGN.md §4). The UI talks to any engine — an in-page Web Worker
 * (browser build), the Node host over a WebSocket, Electron over IPC — with these messages only.
 * Messages from the UI are validated at the engine's boundary (`parseUiMessage`); the UI imports
 * nothing else from the engine but types.
 */
import { z } from "zod";
import type { PortMeta } from "./block";
import type { Diagnostic } from "./diagnostics";
import { MAX_FOLDER_FILES } from "./protocol-folder";
import type { Shape } from "./frame";
import type { PipelineLayout } from "./pipeline/pipeline-layout";
import type { RuntimeEvent, Telemetry } from "./runtime/runtime";

/**
 * Version 1. Optional fields added to a message later (`load`'s `simulateDevices`) keep the
 * version: an engine treats a missing field as before, and the UI and the engine it talks to come
 * from the same build. A change that an older peer would misread raises it.
 */
export const PROTOCOL_VERSION = 1;
/** The versions this engine speaks (its `hello` lists them). */
export const PROTOCOL_VERSIONS: readonly number[] = [PROTOCOL_VERSION];

// ---------------------------------------------------------------------------------------------
// UI → engine

const id = z.number().int().nonnegative();
/**
 * The pipeline came from this computer (the browser build's Open file… / Open folder…): the
 * files of its folder, path → a URL the in-page engine reads (app/engine/protocol-folder.ts);
 * empty when the browser did not say which folder. Engines that read files themselves ignore it.
 */
const localFolder = z
  .record(z.string().max(4096), z.string().max(4096))
  .refine((f) => Object.keys(f).length <= MAX_FOLDER_FILES, "too many files");

export const uiMessageSchema = z.discriminatedUnion("type", [
  z.strictObject({ type: z.literal("hello"), version: z.number().int() }),
  /** Parses and instantiates a pipeline (stopping and disposing a previous one); does not start it. */
  z.strictObject({
    type: z.literal("load"),
    id,
    file: z.string().min(1).max(4096),
    source: z.string().max(4_000_000),
    /**
     * Replace device blocks by simulators of the same shape and rate and output devices by
     * counting sinks (app/engine/pipeline/simulate.ts); default false.
     */
    simulateDevices: z.boolean().optional(),
    folder: localFolder.optional(),
  }),
  /** The diagnostics `mosaic validate` gives for this text (the editor's); loads nothing. */
  z.strictObject({
    type: z.literal("validate"),
    id,
    file: z.string().min(1).max(4096),
    source: z.string().max(4_000_000),
    folder: localFolder.optional(),
  }),
  z.strictObject({ type: z.literal("start"), id }),
  /** Every block type the engine knows, with its metadata (the editor's palette and forms). */
  z.strictObject({ type: z.literal("catalog"), id }),
  z.strictObject({ type: z.literal("stop"), id }),
  /** A live param (validated against the block's schema by the engine). */
  z.strictObject({
    type: z.literal("setParam"),
    id,
    block: z.string().min(1),
    param: z.string().min(1),
    value: z.unknown(),
  }),
  /** A block action, or a built-in: subscribe/unsubscribe (arg: input name or index), reset. */
  z.strictObject({
    type: z.literal("invoke"),
    id,
    block: z.string().min(1),
    action: z.string().min(1),
    arg: z.unknown().optional(),
  }),
  /** Panel data on: the block's frames on `port`, at most `maxRate` events per second. */
  z.strictObject({
    type: z.literal("watch"),
    id,
    block: z.string().min(1),
    port: z.string().optional(),
    maxRate: z.number().positive().max(100_000).optional(),
  }),
  z.strictObject({
    type: z.literal("unwatch"),
    id,
    block: z.string().min(1),
    port: z.string().optional(),
  }),
  /**
   * Records block outputs into one file (a session recording, not a pipeline edit): in the data
   * folder where the host writes files, else in memory and downloaded when it stops. `file`: a
   * plain name (no folder); default from the date and time.
   */
  z.strictObject({
    type: z.literal("record-start"),
    id,
    outputs: z
      .array(z.strictObject({ block: z.string().min(1), port: z.string().min(1).optional() }))
      .min(1)
      .max(4096),
    format: z.enum(["xdf", "edf", "bdf"]),
    file: z.string().min(1).max(200).optional(),
  }),
  /** Finishes the session recording (a download in the browser build). */
  z.strictObject({ type: z.literal("record-stop"), id }),
  /**
   * The UI wrote live values back into the pipeline's text (`source`, comments kept): those
   * values become the file's, so their "changed since loaded" markers clear in every client.
   */
  z.strictObject({
    type: z.literal("params-written"),
    id,
    source: z.string().max(4_000_000),
    values: z
      .array(
        z.strictObject({ block: z.string().min(1), param: z.string().min(1), value: z.unknown() }),
      )
      .max(100_000),
  }),
]);

export type UiMessage = z.infer<typeof uiMessageSchema>;

/**
 * For a `hello` whose version this engine does not speak (or that has none): the sentence the
 * engine's `hello` answers it with (`error`). Undefined for any other message.
 */
export function unsupportedHello(raw: unknown): string | undefined {
  if (raw === null || typeof raw !== "object" || (raw as { type?: unknown }).type !== "hello") {
    return undefined;
  }
  const v = (raw as { version?: unknown }).version;
  if (typeof v === "number" && PROTOCOL_VERSIONS.includes(v)) return undefined;
  const said = v === undefined ? "no version" : `version ${JSON.stringify(v)?.slice(0, 40)}`;
  return `this engine speaks protocol version ${PROTOCOL_VERSIONS.join(", ")}; the hello said ${said}`;
}

/** Validates a message from the UI; returns it or a sentence saying what is wrong. */
export function parseUiMessage(
  raw: unknown,
): { ok: true; msg: UiMessage } | { ok: false; error: string } {
  const r = uiMessageSchema.safeParse(raw);
  if (r.success) return { ok: true, msg: r.data };
  const issue = r.error.issues[0]!;
  const where = issue.path.length ? ` at ${issue.path.map(String).join(".")}` : "";
  return { ok: false, error: `invalid message${where}: ${issue.message}` };
}

// ---------------------------------------------------------------------------------------------
// engine → UI

export interface ActionInfo {
  name: string;
  label: string;
  description?: string;
}

export interface InputRefInfo {
  source: string;
  block: string;
  port: string;
  subscribed: boolean;
}

export interface BlockInfo {
  name: string;
  type: string;
  category: string;
  summary: string;
  help: string;
  worker: string;
  timer: boolean;
  desiredRate: number;
  inputs: InputRefInfo[];
  /** `labels`, `unit`, `grid`: what the port's values are (PortMeta), when known. */
  outputs: ({ name: string; shape: Shape } & PortMeta)[];
  views: string[];
  panel: string;
  /** Params that can be changed while running. */
  live: string[];
  /** Current (validated) params: the engine's, live changes from any client included. */
  params: Record<string, unknown>;
  /**
   * The live params' values in the file (as loaded, or as last written back): a live param whose
   * current value differs was changed since the pipeline was loaded.
   */
  fileParams?: Record<string, unknown>;
  /** JSON Schema (draft 2020-12, input side) of the params: the UI builds its form from it. */
  paramsSchema: unknown;
  actions: ActionInfo[];
  layout?: { x: number; y: number };
  path?: string;
}

/** One block type of the engine's catalog (reply to `catalog`). */
export interface BlockTypeInfo {
  type: string;
  /** Other names files may use (MOSAIC's class names). */
  aliases: string[];
  category: string;
  summary: string;
  help: string;
  /** JSON Schema (draft 2020-12, input side) of the params. */
  paramsSchema: unknown;
  /** Fewest and most inputs (`max` null: any number), and the names of the positions. */
  inputs: { min: number; max: number | null; labels: string[] };
  /** Output port names with the default params (the first is the default port). */
  outputs: string[];
  /** A timer: its ticks carry no values and it needs `DesiredRate`. */
  timer: boolean;
  /** `DesiredRate` must be written in the file. */
  requiresRate: boolean;
  /** Params that can be changed while running. */
  live: string[];
  views: string[];
}

export interface CatalogInfo {
  types: BlockTypeInfo[];
}

export interface GraphInfo {
  file: string;
  blocks: BlockInfo[];
  /** The canvas's group and comment boxes (`Pipeline: { Layout }`), when the file has any. */
  layout?: PipelineLayout;
  /** True when the pipeline was loaded with simulated devices. */
  simulateDevices?: boolean;
  /** The pipeline's text as loaded (or as last written back: `params-written`). */
  source?: string;
}

/** One block's live params now and in the file (a `params` message). */
export interface BlockParamsInfo {
  name: string;
  params: Record<string, unknown>;
  fileParams: Record<string, unknown>;
}

export type EngineState = "empty" | "loaded" | "running" | "stopped" | "finished";

export interface DataMessage {
  type: "data";
  block: string;
  port: string;
  rows: number;
  cols: number;
  /** Event timestamps (UNIX seconds). */
  t: Float64Array;
  /** Values, row-major, `rows * cols` per event. */
  v: Float64Array;
  /** Events left out to honour `maxRate` since the previous message. */
  skipped: number;
}

export type RecordingFormatName = "xdf" | "edf" | "bdf";

/** A session recording (`record-start`), sent while it runs (~4 Hz) and when it ends. */
export interface RecordingStatus {
  state: "recording" | "finished" | "failed";
  /** The file's name (its full path where the host writes files). */
  file: string;
  format: RecordingFormatName;
  /** The outputs recorded, as inputs are written ("Emg", "Myo.imu"). */
  outputs: string[];
  /** Seconds since it started. */
  duration: number;
  bytes: number;
  /** Samples (events) written, all outputs. */
  samples: number;
  /** Kept in memory (browser build): downloaded when it stops. */
  inMemory: boolean;
  /** Why it failed (state "failed"). */
  error?: string;
}

export type EngineMessage =
  | {
      type: "hello";
      version: number;
      /** Every version the engine speaks. */
      versions?: readonly number[];
      engine: string;
      sharedMemory: boolean;
      /** The client's hello named a version the engine does not speak (nothing else follows). */
      error?: string;
    }
  | {
      type: "reply";
      id: number;
      ok: boolean;
      message?: string;
      diagnostics?: Diagnostic[];
      graph?: GraphInfo;
      catalog?: CatalogInfo;
    }
  | { type: "state"; state: EngineState; file?: string }
  /**
   * The loaded pipeline's graph, sent to a client that did not load it: a second tab joining a
   * shared engine (`mosaic serve`), or every other tab after one loads a file.
   */
  | { type: "graph"; graph: GraphInfo }
  | { type: "telemetry"; telemetry: Telemetry }
  | { type: "event"; event: RuntimeEvent }
  | { type: "recording"; recording: RecordingStatus }
  /**
   * Live params changed (a `setParam` from any client) or were written back to the file
   * (`params-written`: then with the file's new text): sent to every client.
   */
  | { type: "params"; blocks: BlockParamsInfo[]; source?: string }
  /**
   * A file for the page to save (browser build, where the engine cannot write files): a finished
   * session recording, a Buffer's or a model's save. Sent only to the page that runs the engine.
   */
  | { type: "download"; name: string; mime: string; bytes: Uint8Array }
  | DataMessage;

/** What the UI holds to talk to an engine, whatever the transport. */
export interface EngineConnection {
  send(msg: UiMessage): void;
  onMessage(handler: (msg: EngineMessage) => void): () => void;
  close(): void;
}
