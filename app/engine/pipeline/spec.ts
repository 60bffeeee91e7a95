/**
 * What the pipeline loader produces (`PipelineSpec`) and the names and patterns of a file's keys.
 * The loader's stages (loader.ts) share these; the runtime reads the spec.
 */
import type { Document } from "yaml";
import type { AnyBlockDefinition } from "../block";
import type { Diagnostic } from "../diagnostics";
import type { PipelineLayout } from "./pipeline-layout";

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
  /** `Layout`: the canvas's group and comment boxes (pipeline-layout.ts). */
  layout?: PipelineLayout;
  /** `Blocks`: modules defining extra block types (docs/writing-blocks.md), as written. */
  blocks?: BlockModuleRef[];
}

/** One entry of `Pipeline: { Blocks: [...] }`: a module file, relative to the pipeline file. */
export interface BlockModuleRef {
  path: string;
  pos: SourcePos;
}

/** The files a `Blocks:` entry may name (ES modules; TypeScript is transpiled on load). */
export const BLOCK_MODULE_RE = /\.(ts|mts|js|mjs)$/;

export interface PipelineSpec {
  file: string;
  blocks: BlockSpec[];
  byName: Map<string, BlockSpec>;
  settings: PipelineSettings;
}

/**
 * What the loader reads at most (README "Pipelines": limits). Every limit is far above what a
 * pipeline needs and keeps loading fast and bounded in memory whatever a file (or a client of
 * `mosaic serve`) sends: each refusal is one positioned error that names the limit.
 */
export interface LoadLimits {
  /** Characters of the file. */
  maxChars: number;
  /** Blocks (top-level entries besides `Pipeline:`). */
  maxBlocks: number;
  /** Values (list items, mapping keys and values) in one block's Params, aliases expanded. */
  maxParamsValues: number;
  /** Values in all Params of the file together, aliases expanded. */
  maxValues: number;
  /** Lists and mappings inside one another (a pipeline needs about 6), aliases expanded. */
  maxDepth: number;
}

/**
 * The limits. Parsing costs about 1 KB of memory per value while the file's syntax tree is built
 * (the `yaml` library's tokens), so 1 MB of the densest text (`0,0,0,…`) peaks near 500 MB; a
 * 10 000-block file is about 0.7 MB and loads in well under a second; a 256 × 512 matrix fits in
 * one block's Params.
 */
export const LOAD_LIMITS: Readonly<LoadLimits> = {
  maxChars: 1_000_000,
  maxBlocks: 10_000,
  maxParamsValues: 1 << 17,
  maxValues: 500_000,
  maxDepth: 32,
};

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
export const SETTINGS_KEYS = ["BatchingMs", "Layout", "Blocks"] as const;
export const BLOCK_NAME_RE = /^[A-Za-z_][A-Za-z0-9_-]*$/;
export const WORKER_RE = /^[A-Za-z_][A-Za-z0-9_-]*$/;
