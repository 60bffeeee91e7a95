import { createElement } from "react";
import { renderToStaticMarkup } from "react-dom/server";
import { afterEach, describe, expect, test, vi } from "vitest";
import type { BlockInfo, BlockTypeInfo } from "../../engine/protocol";
import type { EngineClient } from "../client/engine-client";
import { EngineContext } from "../client/hooks";
import { components, created } from "../test-support/jsx-spy";
import { Inspector, type InspectorProps } from "./inspector";
import type { EditBlock, EditIssue } from "./model";

vi.mock("react/jsx-runtime", async (orig) =>
  (await import("../test-support/jsx-spy")).spyJsx(await orig<object>()),
);
vi.mock("react/jsx-dev-runtime", async (orig) =>
  (await import("../test-support/jsx-spy")).spyJsx(await orig<object>()),
);
afterEach(() => {
  created.length = 0;
});

const block = (over: Partial<EditBlock> = {}): EditBlock => ({
  name: "Filter",
  type: "Bandpass",
  inputs: [
    { source: "Emg", block: "Emg", port: "out", subscribed: true },
    { source: "Timer", block: "Timer", port: "out", subscribed: false },
  ],
  params: { low: 1, high: 40 },
  desiredRate: 250,
  line: 3,
  ...over,
});

const type = (over: Partial<BlockTypeInfo> = {}): BlockTypeInfo => ({
  type: "Bandpass",
  aliases: [],
  category: "Filters",
  summary: "keeps a band",
  help: "A Butterworth band-pass.",
  paramsSchema: {
    type: "object",
    properties: { low: { type: "number" }, high: { type: "number" } },
  },
  inputs: { min: 1, max: 1, labels: [] },
  outputs: ["out"],
  timer: false,
  requiresRate: false,
  live: ["low"],
  views: [],
  ...over,
});

const issue = (message: string, b = "Filter"): EditIssue => ({
  severity: "error",
  message,
  block: b,
  line: 1,
  col: 1,
});

/** Renders the inspector; `log` gets every call of its callbacks, in order. */
function render(
  over: Partial<InspectorProps> = {},
  engineGraph?: { blocks: BlockInfo[] },
): { html: string; log: unknown[][]; props: InspectorProps } {
  const log: unknown[][] = [];
  const props: InspectorProps = {
    block: block(),
    type: type(),
    issues: [],
    runningBlock: undefined,
    onRename: (to) => (log.push(["rename", to]), undefined),
    onDesiredRate: (rate) => (log.push(["desiredRate", rate]), rate === 7 ? "no" : undefined),
    onPath: (path) => (log.push(["path", path]), undefined),
    onInputs: (inputs) => (log.push(["inputs", inputs]), undefined),
    onParam: (param, value) => (log.push(["param", param, value]), Promise.resolve({ ok: true })),
    ...over,
  };
  const client = {
    graph: engineGraph,
    telemetry: undefined,
    state: "loaded",
    onParams: () => () => {},
    onTelemetry: () => () => {},
    onState: () => () => {},
  } as unknown as EngineClient;
  const html = renderToStaticMarkup(
    createElement(EngineContext.Provider, { value: client }, createElement(Inspector, props)),
  );
  return { html, log, props };
}

/** The CommitField rendered with that label. */
const field = (label: string) =>
  components().find(([n, p]) => n === "CommitField" && p.label === label)![1] as {
    value: string;
    placeholder?: string;
    hint?: string;
    inputMode?: string;
    onCommit(s: string): string | undefined;
  };

describe("Inspector markup", () => {
  test("a known type: help, fields and the params form", () => {
    const { html } = render();
    expect(html).toContain('aria-label="Inspector: Filter"');
    expect(html).toContain("1 input(s), comma-separated");
    expect(html).toMatchSnapshot();
  });
  test("an unknown type: no help, no form, the file's type", () => {
    const { html } = render({
      type: undefined,
      block: block({ desiredRate: undefined, path: "logs/f.csv", inputs: [] }),
    });
    expect(html).toContain("Unknown type: no params form.");
    expect(html).toContain('<span class="inspector__type">Bandpass</span>');
    expect(html).toMatchSnapshot();
  });
  test("no type at all", () => {
    expect(render({ type: undefined, block: block({ type: "" }) }).html).toContain(
      '<span class="inspector__type">(no type)</span>',
    );
  });
  test("the block's own problems only, in order", () => {
    const { html } = render({
      issues: [issue("first"), issue("other's", "Emg"), issue("second"), issue("no block", "")],
    });
    expect(html).toContain(
      '<ul class="inspector__issues" aria-label="Problems"><li>first</li><li>second</li></ul>',
    );
    expect(html).toMatchSnapshot();
  });
  test("field values, placeholders and hints by the type's inputs and rate", () => {
    const { html } = render({
      type: type({ requiresRate: true, inputs: { min: 0, max: 0, labels: [] } }),
    });
    expect(field("Name")).toMatchObject({
      value: "Filter",
      hint: "Enter to rename (inputs that name it follow)",
    });
    expect(field("DesiredRate (Hz)")).toMatchObject({
      value: "250",
      inputMode: "decimal",
      placeholder: "required",
    });
    expect(field("Inputs")).toMatchObject({
      value: "Emg, -Timer",
      placeholder: "none",
      hint: "0 input(s), comma-separated; Block.port for another output, -Block: not subscribed",
    });
    expect(field("Path (log)")).toMatchObject({ value: "", placeholder: "not logged" });
    expect([...html.matchAll(/<label for="[^"]*">([^<]*)<\/label>/g)].map((m) => m[1])).toEqual([
      "Name",
      "DesiredRate (Hz)",
      "Inputs",
      "Path (log)",
    ]);
  });
  test("inputs hints: a range and any number", () => {
    render({ type: type({ inputs: { min: 1, max: 3, labels: [] } }) });
    expect(field("Inputs").hint).toMatch(/^1–3 input\(s\)/);
    expect(field("Inputs").placeholder).toBe("e.g. Timer, Emg");
    created.length = 0;
    render({ type: type({ inputs: { min: 2, max: null, labels: [] } }) });
    expect(field("Inputs").hint).toMatch(/^2\+ input\(s\)/);
    created.length = 0;
    render({ type: undefined });
    expect(field("Inputs").hint).toBeUndefined();
    expect(field("Inputs").placeholder).toBe("e.g. Timer, Emg");
    expect(field("DesiredRate (Hz)").placeholder).toBe("inherited from the inputs");
  });
  test("the form gets the block as the engine would list it", () => {
    render();
    const form = components().find(([n]) => n === "ParamsForm")![1];
    expect(form.engineState).toBe("loaded");
    expect(form.block).toEqual({
      name: "Filter",
      type: "Bandpass",
      category: "Filters",
      summary: "keeps a band",
      help: "A Butterworth band-pass.",
      worker: "main",
      timer: false,
      desiredRate: 250,
      inputs: [
        { source: "Emg", block: "Emg", port: "out", subscribed: true },
        { source: "Timer", block: "Timer", port: "out", subscribed: false },
      ],
      outputs: [],
      views: [],
      panel: "",
      live: ["low"],
      params: { low: 1, high: 40 },
      paramsSchema: type().paramsSchema,
      actions: [],
    });
  });
  test("the engine's live values that the text lacks", () => {
    const running = {
      name: "Filter",
      type: "Bandpass",
      live: ["low", "high"],
      params: { low: 5, high: 40 },
      fileParams: { low: 1, high: 30 },
    } as unknown as BlockInfo;
    const { html } = render({ runningBlock: running }, { blocks: [running] });
    expect(html).toContain('data-running-values="1"');
    expect(html).toContain("low = 5 (the text: 1)");
    expect(html).toMatchSnapshot();
  });
});

describe("Inspector callbacks", () => {
  test("rename, path and inputs as typed", () => {
    const { log } = render();
    field("Name").onCommit("Lowpass");
    field("Path (log)").onCommit("");
    field("Path (log)").onCommit("logs/x.csv");
    field("Inputs").onCommit("Emg,  -Timer Myo.imu,");
    field("Inputs").onCommit("");
    expect(log).toEqual([
      ["rename", "Lowpass"],
      ["path", undefined],
      ["path", "logs/x.csv"],
      ["inputs", ["Emg", "-Timer", "Myo.imu"]],
      ["inputs", []],
    ]);
  });
  test("DesiredRate: empty inherits, a positive number is set, else an error", () => {
    const { log } = render();
    const rate = field("DesiredRate (Hz)");
    expect(rate.onCommit("")).toBeUndefined();
    expect(rate.onCommit("12.5")).toBeUndefined();
    expect(rate.onCommit("7")).toBe("no");
    expect(rate.onCommit("0")).toBe("a positive number of Hz");
    expect(rate.onCommit("-1")).toBe("a positive number of Hz");
    expect(rate.onCommit("x")).toBe("a positive number of Hz");
    expect(rate.onCommit("Infinity")).toBe("a positive number of Hz");
    expect(log).toEqual([
      ["desiredRate", undefined],
      ["desiredRate", 12.5],
      ["desiredRate", 7],
    ]);
  });
  test("the form's live and static changes both go to onParam", async () => {
    const { log } = render();
    const form = components().find(([n]) => n === "ParamsForm")![1] as {
      onSet(p: string, v: unknown): Promise<unknown>;
      onEditStatic(p: string, v: unknown): Promise<unknown>;
    };
    await expect(form.onSet("low", 2)).resolves.toEqual({ ok: true });
    await expect(form.onEditStatic("high", 30)).resolves.toEqual({ ok: true });
    expect(log).toEqual([
      ["param", "low", 2],
      ["param", "high", 30],
    ]);
  });
});
