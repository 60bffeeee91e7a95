/**
 * `mosaic run`'s main thread only starts workers, merges telemetry and writes logs: the block
 * catalog, the YAML and schema libraries, the bench and the device simulators are loaded on demand
 * by the commands that need them. Statically imported, they cost the main thread ~20 MiB of heap
 * (the Delsys pipeline's peak RSS 123 → 93 MiB when they went). This checks the bundle the CLI is
 * built from: what `app/cli/main.ts` imports statically, transitively, with esbuild's metafile.
 */
import { build, type Metafile } from "esbuild";
import { describe, expect, it } from "vitest";

/** Every source file in the static import closure of `entry`'s output chunk. */
function staticInputs(meta: Metafile, entry: string): string[] {
  const outputs = meta.outputs;
  const first = Object.keys(outputs).find((o) => outputs[o]!.entryPoint === entry);
  if (!first) throw new Error(`no output for ${entry}`);
  const seen = new Set<string>();
  const queue = [first];
  while (queue.length > 0) {
    const o = queue.pop()!;
    if (seen.has(o)) continue;
    seen.add(o);
    for (const i of outputs[o]!.imports) {
      if (i.kind === "import-statement" && outputs[i.path]) queue.push(i.path);
    }
  }
  return [...seen].flatMap((o) => Object.keys(outputs[o]!.inputs));
}

describe("the CLI's main thread", () => {
  it("statically imports no block, no YAML or schema library, no bench and no loader", async () => {
    const r = await build({
      entryPoints: ["app/cli/main.ts"],
      bundle: true,
      platform: "node",
      format: "esm",
      splitting: true,
      outdir: "/nonexistent-out",
      write: false,
      metafile: true,
      logLevel: "silent",
      external: [
        "serialport",
        "@serialport/*",
        "@abandonware/noble",
        "electron",
        "koffi",
        "esbuild",
      ],
    });
    const inputs = staticInputs(r.metafile, "app/cli/main.ts");
    expect(inputs).toContain("app/host/host.ts");
    const heavy = inputs.filter((f) =>
      /^(app\/blocks\/|app\/engine\/pipeline\/|app\/cli\/bench|node_modules\/(zod|yaml)\/)/.test(f),
    );
    expect(heavy).toEqual([]);
  });
});
