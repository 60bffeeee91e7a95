import { mkdir, readFile, writeFile } from "node:fs/promises";
import { dirname, isAbsolute, resolve } from "node:path";
import type { Resources } from "../engine/block";

/** File access for blocks: relative paths are resolved against the pipeline file's folder. */
export function nodeResources(baseDir: string): Resources {
  return {
    resolve: (p: string) => (isAbsolute(p) ? p : resolve(baseDir, p)),
    readText: async (p: string) => {
      const full = isAbsolute(p) ? p : resolve(baseDir, p);
      try {
        return await readFile(full, "utf8");
      } catch (e) {
        const code = (e as NodeJS.ErrnoException).code;
        if (code === "ENOENT") throw new Error(`file not found: ${full}`);
        if (code === "EACCES") throw new Error(`no permission to read ${full}`);
        if (code === "EISDIR") throw new Error(`${full} is a folder, not a file`);
        throw new Error(`cannot read ${full}: ${(e as Error).message}`);
      }
    },
    writeText: async (p: string, text: string) => {
      const full = isAbsolute(p) ? p : resolve(baseDir, p);
      try {
        await mkdir(dirname(full), { recursive: true });
        await writeFile(full, text, "utf8");
      } catch (e) {
        const code = (e as NodeJS.ErrnoException).code;
        if (code === "EACCES") throw new Error(`no permission to write ${full}`);
        if (code === "ENOSPC") throw new Error(`the disk is full: cannot write ${full}`);
        throw new Error(`cannot write ${full}: ${(e as Error).message}`);
      }
    },
  };
}
