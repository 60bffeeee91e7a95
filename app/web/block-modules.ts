/**
 * User block modules in the browser build (docs/writing-blocks.md): a pipeline served with the
 * page (a bundled URL) may name JavaScript modules beside it. Each is fetched relative to the
 * pipeline, its `mosaic/sdk` imports bound to this worker's SDK object, and imported from a blob:
 * URL. There is no bundler here: a module must be one self-contained `.js`/`.mjs` file (no
 * relative imports, no TypeScript — `mosaic serve` and `mosaic run` transpile and bundle those).
 */
import { errorMessage } from "../engine/diagnostics";
import { installSdk, sdkModuleSource, type ModuleLoadResult } from "../engine/user-blocks";

/** Where the browser build finds block modules (not in a folder opened from this computer). */
const SERVED_ONLY =
  "the browser build loads block modules from the web server, beside a pipeline served with the page";

let sdkUrl: string | undefined;

/** A blob: URL of the module that stands for `mosaic/sdk` (made once). */
function sdkModuleUrl(): string {
  installSdk();
  sdkUrl ??= URL.createObjectURL(new Blob([sdkModuleSource()], { type: "text/javascript" }));
  return sdkUrl;
}

/** The module's text with its `mosaic/sdk` imports pointing at `url`. */
export function bindSdkImports(text: string, url: string): string {
  return text.replace(
    /(\bfrom\s*|\bimport\s*\(\s*|\bimport\s+)(["'])@?mosaic\/sdk\2/g,
    (_m, lead: string, q: string) => `${lead}${q}${url}${q}`,
  );
}

/** Loads the module at `path` (relative to the page, as the pipeline's file is). */
export async function loadBrowserBlockModule(path: string): Promise<ModuleLoadResult> {
  const inputs = [path];
  if (/\.m?ts$/.test(path)) {
    return {
      ok: false,
      message:
        "the browser build cannot transpile TypeScript: give it the module as .js, or run the pipeline with mosaic serve",
      inputs,
    };
  }
  const url = new URL(path, self.location.href);
  let text: string;
  try {
    const r = await fetch(url);
    if (!r.ok) {
      const why = `cannot fetch it from ${url.href}: HTTP ${r.status}`;
      return { ok: false, message: `${why} (${SERVED_ONLY})`, inputs };
    }
    text = await r.text();
  } catch (e) {
    return { ok: false, message: `cannot fetch it: ${errorMessage(e)}`, inputs };
  }
  const code = `${bindSdkImports(text, sdkModuleUrl())}\n//# sourceURL=${url.href}\n`;
  const blob = URL.createObjectURL(new Blob([code], { type: "text/javascript" }));
  try {
    const exports = (await import(/* @vite-ignore */ blob)) as Record<string, unknown>;
    return { ok: true, exports, inputs };
  } catch (e) {
    const kind = e instanceof SyntaxError ? "it does not parse" : "its top level threw";
    return { ok: false, message: `${kind}: ${errorMessage(e)}`, inputs };
  } finally {
    URL.revokeObjectURL(blob);
  }
}
