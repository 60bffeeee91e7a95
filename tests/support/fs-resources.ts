/**
 * A `Resources` backed by node:fs for tests: paths resolve against a base folder (default: the
 * repository root), like the host resolves them against the pipeline file's folder.
 */
import { mkdir, readFile, writeFile } from "node:fs/promises";
import { dirname, isAbsolute, resolve } from "node:path";
import { fileURLToPath } from "node:url";
import type { Resources } from "../../app/engine";

export const REPO_ROOT = fileURLToPath(new URL("../../", import.meta.url));

export function fsResources(base: string = REPO_ROOT): Resources {
  const res = (p: string): string => (isAbsolute(p) ? p : resolve(base, p));
  return {
    resolve: res,
    readText: (p) => readFile(res(p), "utf8"),
    writeText: async (p, text) => {
      await mkdir(dirname(res(p)), { recursive: true });
      await writeFile(res(p), text, "utf8");
    },
  };
}

/** In-memory files, for tests that need a small recording without touching the disk. */
export function memoryResources(files: Record<string, string>): Resources {
  return {
    resolve: (p) => p,
    writeText: (p, text) => {
      files[p] = text;
      return Promise.resolve();
    },
    readText: (p) => {
      const text = files[p];
      return text === undefined
        ? Promise.reject(new Error(`ENOENT: no such file '${p}'`))
        : Promise.resolve(text);
    },
  };
}
