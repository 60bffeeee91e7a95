/**
 * Files written for the original MOSAIC (issue 13): our own test pipelines in the original's
 * layouts and names (tests/fixtures/mosaic-original/, one construct per file), each checked for
 * what it loads as (the exact warnings), the params our blocks receive, and that `mosaic format`
 * leaves it as it is. See docs/mosaic-compatibility.md.
 */
import { copyFileSync, readdirSync, readFileSync } from "node:fs";
import { join } from "node:path";
import { beforeAll, describe, expect, test } from "vitest";
import { catalog } from "../../app/blocks/catalog";
import { formatDiagnostic } from "../../app/engine/diagnostics";
import { PipelineDocument } from "../../app/engine/pipeline/document";
import { loadPipeline } from "../../app/engine/pipeline/loader";
import { runVirtualPipeline } from "../../app/engine/testing";
import { initDspForTests } from "../support/wasm";
import { requireBuild, ROOT, runCli, tempDir } from "./helpers";

const DIR = join(ROOT, "tests/fixtures/mosaic-original");
const FILES = readdirSync(DIR)
  .filter((f) => f.endsWith(".yaml"))
  .sort();

function load(name: string) {
  const text = readFileSync(join(DIR, name), "utf8");
  const r = loadPipeline(text, name, catalog);
  const errors = r.diagnostics.filter((d) => d.severity === "error").map(formatDiagnostic);
  const warnings = r.diagnostics.filter((d) => d.severity === "warning");
  const params = (block: string) => r.spec?.byName.get(block)?.params;
  return { text, r, errors, warnings, params };
}

/** A converted block's warning, as the loader words it. */
const converted = (file: string, at: string, block: string, type: string, to: string) =>
  `${file}:${at}: warning: block '${block}' (${type}): converted MOSAIC positional Params to ${to}`;

describe("files in the original MOSAIC's layout and names", () => {
  test("there is one file per construct", () => {
    expect(FILES).toEqual([
      "batch-with-stimulus.yaml",
      "closing-brackets.yaml",
      "device-types.yaml",
      "flow-comments.yaml",
      "incremental-with-tac.yaml",
      "old-names.yaml",
      "pair-params.yaml",
      "streamlined-sender.yaml",
      "tabs.yaml",
    ]);
  });

  test("closing brackets in column 1", () => {
    const f = "closing-brackets.yaml";
    const { errors, warnings, params } = load(f);
    expect(errors).toEqual([]);
    expect(warnings.map(formatDiagnostic)).toEqual([
      converted(f, "5:56", "wave", "SinGenerator", '{"Components":3}'),
      converted(
        f,
        "7:34",
        "labels",
        "Trigger",
        '{"Labels":{"idle":[0,0],"grip":[1,0],"point":[0,1]}}',
      ),
      converted(
        f,
        "12:72",
        "model",
        "IncrementalPredictor",
        '{"Model":"ridge","Inputs":3,"Outputs":2,"Lambda":1,"Intercept":false}',
      ),
      converted(f, "14:33", "smooth", "Filter", '{"Numerator":[0.25,0.25],"Denominator":[1,-0.5]}'),
      converted(f, "18:56", "tripled", "Function", '{"Operation":"multiply","Value":3}'),
    ]);
    expect(params("labels")).toMatchObject({
      Labels: { idle: [0, 0], grip: [1, 0], point: [0, 1] },
    });
    expect(params("halved")).toMatchObject({ Operation: "multiply", Value: 0.5 });
  });

  test("comments inside flow collections", () => {
    const f = "flow-comments.yaml";
    const { errors, warnings, params } = load(f);
    expect(errors).toEqual([]);
    expect(warnings.map(formatDiagnostic)).toEqual([
      converted(
        f,
        "8:11",
        "cue",
        "Stimulus",
        '{"Capture":2,"Tasks":[{"Label":"task1","Target":[0,0,1]},{"Label":"task2","Target":[1,0,0]}]}',
      ),
      converted(f, "18:13", "lowpass", "Filter", '{"Numerator":[0.5,0.5],"Denominator":[1,0]}'),
    ]);
    expect(params("cue")).toMatchObject({ Capture: 2 });
  });

  test("tab-indented keys, trailing spaces, no final line break", () => {
    const f = "tabs.yaml";
    const { text, errors, warnings, params } = load(f);
    expect(text).toContain("\n\tType: Function,");
    expect(text.endsWith("\n")).toBe(false);
    expect(errors).toEqual([]);
    expect(warnings.map(formatDiagnostic)).toEqual([
      converted(f, "4:56", "wave", "SinGenerator", '{"Components":2}'),
      converted(f, "10:10", "square", "Function", '{"Operation":"power","Exponent":2}'),
    ]);
    expect(params("square")).toEqual({ Operation: "power", Exponent: 2 });
  });

  test("`key: value` items and numbers as their source text", () => {
    const f = "pair-params.yaml";
    const { errors, warnings, params } = load(f);
    expect(errors).toEqual([]);
    expect(warnings.map((w) => [w.code, w.block])).toEqual([
      ["legacy-converted", "left"],
      ["legacy-converted", "right"],
      ["legacy-converted", "both"],
      ["legacy-converted", "labels"],
      ["legacy-converted", "model"],
      ["legacy-converted", "ramp"],
      ["legacy-converted", "control"],
    ]);
    expect(formatDiagnostic(warnings[2]!)).toBe(
      converted(f, "7:56", "both", "Joiner", '{"Trigger":"right"}'),
    );
    // [ timerBlockName: right ] is the string "timerBlockName:right" (no space: see the docs).
    expect(params("both")).toEqual({ Trigger: "right" });
    // `2.50:` is the label "2.50" (its source text), `rest:   0;…` the label rest.
    const labels = (params("labels") as { Labels: Record<string, number[]> }).Labels;
    expect(Object.keys(labels)).toEqual(["rest", "power", "2.50"]);
    expect(labels["2.50"]![7]).toBe(1);
    expect(params("right")).toMatchObject({ Components: 1 });
    expect(params("ramp")).toMatchObject({ Numerator: [0.5, 0.5], Denominator: [1, 0] });
    expect(params("control")).toMatchObject({ Strategy: "direct" });
  });

  test("old type names and keys: one warning per block says what it became", () => {
    const f = "old-names.yaml";
    const { errors, warnings, params, r } = load(f);
    expect(errors).toEqual([]);
    const was = "the original MOSAIC's old name of";
    expect(warnings.map(formatDiagnostic)).toEqual([
      `${f}:4:15: warning: block 'fast': 'Timer' is ${was} ScheduledTimer; loading it as ScheduledTimer`,
      `${f}:5:15: warning: block 'slow': 'TimerDecimator' is ${was} DecimatorTimer (Params: [factor], every factor-th tick); loading it as DecimatorTimer with DesiredRate 250 Hz (fast's 1000 Hz / 4)`,
      `${f}:6:17: warning: block 'slower': 'TimerDecimator' is ${was} DecimatorTimer (Params: [factor], every factor-th tick); loading it as DecimatorTimer with DesiredRate 25 Hz (slow's 250 Hz / 10)`,
      converted(f, "7:55", "wave", "SinGenerator", '{"Components":4}'),
      `${f}:8:15: warning: block 'gain': 'Func_Multiplier' is ${was} Function multiply (Params: [factor]); loading it as Function with Params {"Operation":"multiply","Value":2.5}`,
      `${f}:9:15: warning: block 'rect': 'Func_Rectifier' is ${was} Function abs; loading it as Function with Params {"Operation":"abs"}`,
      `${f}:10:15: warning: block 'diff': 'vectorialFunction' is a misspelling of VectorialFunction (the original MOSAIC's type names are case-sensitive); loading it as VectorialFunction with Params {"Operation":"subtract"}`,
      converted(
        f,
        "11:55",
        "win",
        "SlidingWindow",
        '{"Length":50,"Step":25,"WindowFunction":"none"}',
      ),
      `${f}:12:14: warning: block 'mav': 'MeanAverageValue' is the old name of MeanAbsoluteValue; loading it as MeanAbsoluteValue`,
      `${f}:13:57: warning: block 'held': Path '' logged to the root of the drive in the original MOSAIC; here it logs to held.txt in the log folder (the pipeline's folder, or mosaic run --log-dir)`,
      `${f}:15:14: warning: block 'arm': 'MYO' is the old name of Myo; loading it as Myo`,
      `${f}:4:41: warning: OutputType (on 3 blocks: fast, wave, gain) ignored: OutputType is an output-shape hint of the original's older files; our blocks take their output shape from their inputs and params`,
    ]);
    const spec = (b: string) => r.spec!.byName.get(b)!;
    expect(
      ["fast", "slow", "slower", "gain", "rect", "diff", "mav", "arm"].map((b) => spec(b).type),
    ).toEqual([
      "ScheduledTimer",
      "DecimatorTimer",
      "DecimatorTimer",
      "Function",
      "Function",
      "VectorialFunction",
      "MeanAbsoluteValue",
      "Myo",
    ]);
    expect([spec("slow").desiredRate, spec("slower").desiredRate]).toEqual([250, 25]);
    expect(params("gain")).toEqual({ Operation: "multiply", Value: 2.5, Exponent: 2 });
    expect(params("rect")).toMatchObject({ Operation: "abs" });
    expect(params("diff")).toMatchObject({ Operation: "subtract" });
    expect(spec("held").path).toBe(".");
  });

  test("old names run as what they became (rates from the decimation factor)", async () => {
    initDspForTests();
    const { text } = load("old-names.yaml");
    const run = await runVirtualPipeline(
      text
        .split("\n")
        .filter((l) => !l.startsWith("arm"))
        .join("\n"),
      { catalog, duration: 1, file: "old-names.yaml" },
    );
    const period = (b: string) => {
      const t = run.outputs.get(b)!.t;
      return (t[t.length - 1]! - t[0]!) / (t.length - 1);
    };
    expect(period("slow")).toBeCloseTo(1 / 250, 12);
    expect(period("slower")).toBeCloseTo(1 / 25, 12);
    const wave = run.outputs.get("wave")!.v;
    const gain = run.outputs.get("gain")!.v;
    expect(gain[10]![2]).toBeCloseTo(2.5 * wave[10]![2]!, 12);
    expect(run.outputs.get("rect")!.v[10]![2]).toBeCloseTo(Math.abs(gain[10]![2]!), 12);
    expect(run.logs.files.has("./held.txt")).toBe(true);
  });
});

describe("the editor converts them to named params", () => {
  test("old names get the Type they load as (and a TimerDecimator its rate); nothing else changes", () => {
    const { text, r } = load("old-names.yaml");
    const d = PipelineDocument.parse(text, "old-names.yaml");
    for (const b of d.blockNames())
      if (d.block(b).positionalParams) d.convertLegacyParams(b, catalog);
    const out = d.toString();
    expect(out).toContain(
      "slow: { Type: DecimatorTimer, DesiredRate: 250, Inputs: [ fast ], Params: {} }",
    );
    expect(out).toContain(
      "gain: { Type: Function, Inputs: [ wave ], Params: { Operation: multiply, Value: 2.5 }, OutputType: 4d }",
    );
    expect(out).toContain("arm: { Type: MYO, Inputs: [ armClock ], Params: {} }");
    const again = loadPipeline(out, "old-names.yaml", catalog);
    expect(again.diagnostics.filter((x) => x.severity === "error")).toEqual([]);
    expect(again.diagnostics.filter((x) => x.code === "legacy-converted")).toEqual([]);
    for (const b of r.spec!.blocks) {
      const after = again.spec!.byName.get(b.name)!;
      expect([after.type, after.params, after.desiredRate], b.name).toEqual([
        b.type,
        b.params,
        b.desiredRate,
      ]);
    }
  });
});

describe("types that do not load", () => {
  const errorsOf = (src: string) =>
    loadPipeline(src, "p.yaml", catalog)
      .diagnostics.filter((d) => d.severity === "error")
      .map(formatDiagnostic);

  test("HannesArm: the original's HannesGUI, loaded as that with one warning", () => {
    const r = loadPipeline(
      "t: { Type: ScheduledTimer, DesiredRate: 25 }\nh: { Type: HannesArm, Inputs: [ t ], Params: [ localhost, 8889 ] }\n",
      "p.yaml",
      catalog,
    );
    expect(r.diagnostics.map(formatDiagnostic)).toEqual([
      `p.yaml:2:12: warning: block 'h': 'HannesArm' is the original MOSAIC's old name of HannesGUI; loading it as HannesGUI with Params {"Host":"localhost","Port":8889}`,
    ]);
  });

  test("FBGS and hyperplaneFitting: no public source defines them", () => {
    expect(
      errorsOf(
        "f: { Type: FBGS, Params: [ 0, 1 ] }\nh: { Type: hyperplaneFitting, Inputs: [ f ], Params: [ 4 ] }\n",
      ),
    ).toEqual([
      "p.yaml:1:12: error: block 'f': unknown block type 'FBGS': no public source of the original MOSAIC defines 'FBGS' (it is not a typo of a block type here), so there is nothing to load it as",
      "p.yaml:2:12: error: block 'h': unknown block type 'hyperplaneFitting': no public source of the original MOSAIC defines 'hyperplaneFitting' (it is not a typo of a block type here), so there is nothing to load it as",
    ]);
  });

  test("a bad decimation factor and an input without a rate", () => {
    expect(
      errorsOf(
        "t: { Type: ScheduledTimer, DesiredRate: 100 }\nd: { Type: TimerDecimator, Inputs: [ t ], Params: [ 2.5 ] }\n",
      ),
    ).toEqual([
      "p.yaml:2:51: error: block 'd' (TimerDecimator → DecimatorTimer): cannot convert positional Params [2.5]: decimation factor '2.5' is not a whole number",
    ]);
    expect(
      errorsOf(
        "s: { Type: SinGenerator, Inputs: [ t ], Params: [ 1 ] }\nt: { Type: ScheduledTimer, DesiredRate: 100 }\nd: { Type: TimerDecimator, Inputs: [ s ], Params: [ 2 ] }\n",
      ),
    ).toEqual([
      "p.yaml:3:51: error: block 'd' (DecimatorTimer): its DesiredRate is its input's divided by 2, but input 's' has no known rate (expected a timer input with a DesiredRate)",
    ]);
  });
});

describe("mosaic format leaves them as they are", () => {
  beforeAll(() => requireBuild());

  test("format --check: unchanged, except the missing final line break", () => {
    const files = FILES.map((f) => join("tests/fixtures/mosaic-original", f));
    const r = runCli(["format", "--check", ...files], { timeoutMs: 120_000 });
    expect(r.stderr).toBe("");
    for (const f of files) {
      expect(r.stdout).toContain(
        f.endsWith("tabs.yaml") ? `${f}: would change` : `${f}: unchanged`,
      );
    }
    const dir = tempDir();
    const copy = join(dir, "tabs.yaml");
    copyFileSync(join(DIR, "tabs.yaml"), copy);
    expect(runCli(["format", copy]).code).toBe(0);
    expect(readFileSync(copy, "utf8")).toBe(`${readFileSync(join(DIR, "tabs.yaml"), "utf8")}\n`);
    expect(runCli(["format", "--check", copy]).stdout).toContain(`${copy}: unchanged`);
  });
});
