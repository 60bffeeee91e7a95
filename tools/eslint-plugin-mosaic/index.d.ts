// Types for the plain-JS plugin (so TypeScript tests can import it).
import type { ESLint, Rule } from "eslint";

export type Layer =
  | "engine"
  | "blocks"
  | "bridges"
  | "host"
  | "ui"
  | "web"
  | "electron"
  | "cli"
  | "devices"
  | "core-wasm"
  | "tests"
  | "tooling";

/** Folder prefix (repo-relative) → layer. */
export const LAYER_FOLDERS: ReadonlyArray<readonly [string, Layer]>;
/** Source layer → the layers it may import; `*` = anything. */
export const ALLOWED: Readonly<Record<Layer, readonly (Layer | "*")[]>>;
/** Layer of a repo-relative, '/'-separated path. */
export function layerOf(rel: string): Layer | undefined;

declare const plugin: ESLint.Plugin & { rules: { layers: Rule.RuleModule } };
export default plugin;
