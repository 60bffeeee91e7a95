/**
 * What the pipeline loader produces (`PipelineSpec`) and the names and patterns of a file's keys.
 * The loader's stages (loader.ts) share these; the runtime reads the spec.
 */
import type { Document } from "yaml";
import type { AnyBlockDefinition } from "../block";
import type { Diagnostic } from "../diagnostics";

export type QueuePolicy = "drop-oldest" | "drop-newest" | "latest";
export const QUEUE_POLICIES: readonly QueuePolicy[] = ["drop-oldest", "drop-newest", "latest"];

export interface SourcePos {
  line: number;
  col: number;
}

export interface InputRef {
  /** As written, without the leading '-'. */
  source: string;
  block: string;
  /** Output port of the source block ("" = its default port until resolved). */
  port: string;
  subscribed: boolean;
  pos: SourcePos;
}

export interface QueueSpec {
  policy: QueuePolicy;
  /** Capacity in events; undefined = default (one second of data, at least 64 events). */
  capacity: number | undefined;
}

export interface BlockSpec {
  name: string;
  type: string;
  def: AnyBlockDefinition;
  /** Validated params (zod output: defaults applied). */
  params: unknown;
  desiredRate: number | undefined;
  inputs: InputRef[];
  /** Log this block's output (folder, or a file when it has an extension). */
  path: string | undefined;
  worker: string;
  /** `BatchingMs`: this block's timers' batching interval, ms (overrides the pipeline's). */
  batchingMs: number | undefined;
  queue: QueueSpec;
  layout: { x: number; y: number } | undefined;
  /** Output port names (first is the default). */
  outputs: readonly string[];
  legacy: boolean;
  pos: SourcePos;
  paramsPos: SourcePos;
  inputsPos: SourcePos;
  /** Position of each param key, for errors found after validation. */
  paramPos: Record<string, SourcePos>;
}

/** Settings of the whole pipeline: the reserved top-level entry `Pipeline: { … }`. */
export interface PipelineSettings {
  /** `BatchingMs`: how long a timer's ticks may wait to go out together, ms (DESIGN.md §3). */
  batchingMs: number | undefined;
}

export interface PipelineSpec {
  file: string;
  blocks: BlockSpec[];
  byName: Map<string, BlockSpec>;
  settings: PipelineSettings;
}

export interface LoadResult {
  spec: PipelineSpec | undefined;
  diagnostics: Diagnostic[];
  ok: boolean;
  /** The parsed document (for editors that keep comments through an edit). */
  doc: Document | undefined;
}

/** The keys a block may have (MOSAIC's five, then ours). */
export const BLOCK_KEYS = [
  "Type",
  "DesiredRate",
  "Inputs",
  "Params",
  "Path",
  "Layout",
  "Worker",
  "Queue",
  "BatchingMs",
] as const;
/** The reserved top-level name for pipeline settings (a mapping without `Type`). */
export const SETTINGS_KEY = "Pipeline";
export const SETTINGS_KEYS = ["BatchingMs"] as const;
export const BLOCK_NAME_RE = /^[A-Za-z_][A-Za-z0-9_-]*$/;
export const WORKER_RE = /^[A-Za-z_][A-Za-z0-9_-]*$/;
