/**
 * A `Resources` backed by node:fs for tests: paths resolve against a base folder (default: the
 * repository root), like the host resolves them against the pipeline file's folder.
 */
import { readFile } from "node:fs/promises";
import { isAbsolute, resolve } from "node:path";
import { fileURLToPath } from "node:url";
import type { Resources } from "../../app/engine";

export const REPO_ROOT = fileURLToPath(new URL("../../", import.meta.url));

export function fsResources(base: string = REPO_ROOT): Resources {
  const res = (p: string): string => (isAbsolute(p) ? p : resolve(base, p));
  return {
    resolve: res,
    readText: (p) => readFile(res(p), "utf8"),
  };
}

/** In-memory files, for tests that need a small recording without touching the disk. */
export function memoryResources(files: Record<string, string>): Resources {
  return {
    resolve: (p) => p,
    readText: (p) => {
      const text = files[p];
      return text === undefined
        ? Promise.reject(new Error(`ENOENT: no such file '${p}'`))
        : Promise.resolve(text);
    },
  };
}
