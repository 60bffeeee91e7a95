/**
 * A pipeline opened from this computer in the browser build (issue 17, defect 5). A page knows no
 * paths: for a file picked alone it does not even know its folder. The page sends the files of
 * the folder it was given (`load`'s and `validate`'s `folder`: path relative to that folder →
 * a blob: URL the in-page engine may fetch; empty when the browser did not say), and the engine
 * resolves a block's relative path (a FilePlayer's File, a model) against the pipeline file's
 * place in it. A file that is not there is one clear error naming the path and what to do.
 */

/** The files of the opened folder: path relative to it ('/'-separated) → a URL to read it. */
export type LocalFolder = Readonly<Record<string, string>>;

/** At most this many files of a folder are offered to the engine. */
export const MAX_FOLDER_FILES = 20_000;

/** Words of the error for a file picked alone (the page offers to open its folder). */
export const OPEN_ITS_FOLDER = "open its folder (Open folder…)";

/** `a/b/../c` → `a/c`; undefined when it leaves the folder (`../` above its top). */
export function normalizePath(path: string): string | undefined {
  const out: string[] = [];
  for (const part of path.replace(/\\/g, "/").split("/")) {
    if (part === "" || part === ".") continue;
    if (part === "..") {
      if (out.length === 0) return undefined;
      out.pop();
    } else out.push(part);
  }
  return out.join("/");
}

const isAbsolute = (p: string): boolean => p.startsWith("/") || /^[A-Za-z]:[\\/]/.test(p);
const isUrl = (p: string): boolean => /^[a-z][a-z0-9+.-]*:\/\//i.test(p);

export type Resolved =
  { ok: true; path: string; url: string } | { ok: false; path: string; message: string };

/**
 * Where `path`, written in the pipeline `file` (its place in the folder), is in `folder`; a URL
 * is itself. The message of a miss says why, in words for the person who opened the file.
 */
export function resolveInFolder(folder: LocalFolder, file: string, path: string): Resolved {
  if (isUrl(path)) return { ok: true, path, url: path };
  const name = file.split("/").pop() ?? file;
  if (Object.keys(folder).length === 0) {
    return {
      ok: false,
      path,
      message:
        `the browser does not say which folder ${name} is in: ${OPEN_ITS_FOLDER} to give ` +
        "the page the pipeline and its data",
    };
  }
  if (isAbsolute(path)) {
    return {
      ok: false,
      path,
      message:
        "an absolute path: the browser build reads only the files of the opened folder " +
        `(write it relative to ${name})`,
    };
  }
  const dir = file.includes("/") ? file.slice(0, file.lastIndexOf("/")) : "";
  const joined = normalizePath(dir === "" ? path : `${dir}/${path}`);
  const top = file.split("/")[0] ?? "";
  if (joined === undefined || (top !== "" && file.includes("/") && !joined.startsWith(`${top}/`))) {
    return {
      ok: false,
      path,
      message: `'${path}' is outside the opened folder '${top}': open the folder that holds both`,
    };
  }
  const url = folder[joined];
  if (url === undefined) {
    return { ok: false, path: joined, message: `not in the opened folder (no file ${joined})` };
  }
  return { ok: true, path: joined, url };
}
