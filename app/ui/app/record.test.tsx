import { createElement } from "react";
import { renderToStaticMarkup } from "react-dom/server";
import { afterEach, describe, expect, test, vi } from "vitest";
import type { GraphInfo, RecordingStatus } from "../../engine/protocol";
import type { EngineClient, Reply } from "../client/engine-client";
import { EngineContext } from "../client/hooks";
import { clearHooks, hooks } from "../test-support/jsx-spy";
import { RecordControl } from "./record";

/** A DOM element's props as the tests call them. */
type Props = Record<string, unknown> & { className?: string; type?: string };

/**
 * The props of every DOM element rendered (tag and props, in order), and what the tests do while
 * it renders: the first element an action matches gets it at once, as a click in the page would
 * (a state update while rendering: the server renderer renders the component again with it).
 * Effects, state updates and initial states are in jsx-spy's `hooks`.
 */
const spy = vi.hoisted(() => {
  const elements: [string, Props][] = [];
  const actions: { match(tag: string, p: Props): boolean; act(p: Props): void }[] = [];
  const capture =
    (jsx: (...a: unknown[]) => unknown) =>
    (type: unknown, props: Props, ...rest: unknown[]) => {
      if (typeof type === "string") {
        elements.push([type, props]);
        const k = actions.findIndex((a) => a.match(type, props));
        if (k >= 0) actions.splice(k, 1)[0]!.act(props);
      }
      return jsx(type, props, ...rest);
    };
  return { elements, actions, capture };
});
vi.mock("react/jsx-dev-runtime", async (orig) => {
  const m = await orig<typeof import("react/jsx-dev-runtime")>();
  return { ...m, jsxDEV: spy.capture(m.jsxDEV as (...a: unknown[]) => unknown) };
});
vi.mock("react/jsx-runtime", async (orig) => {
  const m = await orig<typeof import("react/jsx-runtime")>();
  return {
    ...m,
    jsx: spy.capture(m.jsx as (...a: unknown[]) => unknown),
    jsxs: spy.capture(m.jsxs as (...a: unknown[]) => unknown),
  };
});
vi.mock("react", async (orig) =>
  (await import("../test-support/jsx-spy")).spyReact(await orig<typeof import("react")>()),
);
afterEach(() => {
  spy.elements.length = 0;
  spy.actions.length = 0;
  clearHooks();
});

const out = (name: string, rows: number, cols: number) => ({ name, shape: { rows, cols } });
const graph = {
  file: "p.yaml",
  blocks: [
    {
      name: "Timer",
      type: "Timer",
      category: "Sources",
      timer: true,
      desiredRate: 100,
      outputs: [out("out", 0, 0)],
    },
    {
      name: "Emg",
      type: "MyoEmg",
      category: "Devices",
      desiredRate: 200,
      outputs: [out("out", 1, 8), out("imu", 1, 1), out("none", 0, 0)],
    },
    {
      name: "Filter",
      type: "Bandpass",
      category: "Filters",
      desiredRate: 12.345,
      outputs: [out("out", 2, 4)],
    },
    {
      name: "Pick",
      type: "Trigger",
      category: "Events",
      desiredRate: 0,
      outputs: [out("out", 1, 1)],
    },
  ],
} as unknown as GraphInfo;

const status = (over: Partial<RecordingStatus> = {}): RecordingStatus => ({
  state: "recording",
  file: "/data/recordings/rec.xdf",
  format: "xdf",
  outputs: ["Emg", "Emg.imu"],
  duration: 12.34,
  bytes: 1_234_567,
  samples: 24_600,
  inMemory: false,
  ...over,
});

/** Renders the control; `log` gets every call to the engine and to notify, in order. */
function render(
  opts: {
    graph?: GraphInfo;
    running?: boolean;
    recording?: RecordingStatus;
    engine?: string;
    reply?: Reply;
  } = {},
) {
  const log: unknown[][] = [];
  const reply = (r: Reply) => Promise.resolve(opts.reply ?? r);
  const client = {
    recording: opts.recording,
    engineName: opts.engine ?? "node",
    connected: true,
    sharedMemory: true,
    onRecording: (cb: unknown) => {
      log.push(["onRecording", typeof cb]);
      return () => log.push(["offRecording"]);
    },
    onHello: () => () => {},
    recordStart: (outputs: unknown, format: unknown) => {
      log.push(["recordStart", outputs, format]);
      return reply({ ok: true, message: "recording to rec.xdf" } as Reply);
    },
    recordStop: () => {
      log.push(["recordStop"]);
      return reply({ ok: true } as Reply);
    },
  } as unknown as EngineClient;
  const notify = (message: string, level?: string) => log.push(["notify", message, level]);
  const html = renderToStaticMarkup(
    createElement(
      EngineContext.Provider,
      { value: client },
      createElement(RecordControl, {
        graph: opts.graph ?? graph,
        running: opts.running ?? true,
        notify,
      }),
    ),
  );
  return { html, log, elements: [...spy.elements] };
}

const settle = () => new Promise((r) => setTimeout(r, 0));
/** Clicks the Record… button while it renders (opens the dialog). */
const openDialog = () =>
  spy.actions.push({
    match: (tag, p) => tag === "button" && p.className === "record-button",
    act: (p) => (p.onClick as () => void)(),
  });
/** The props of the last element rendered with that tag (and `p`): the latest render's. */
const the = (elements: [string, Props][], tag: string, p: (p: Props) => boolean = () => true) =>
  elements.findLast(([t, props]) => t === tag && p(props))![1];

describe("RecordControl markup", () => {
  test("stopped pipeline: Record… disabled", () => {
    const { html, log } = render({ running: false });
    expect(html).toContain("disabled");
    expect(html).toMatchSnapshot();
    expect(log).toEqual([]);
  });
  test("running, nothing recorded yet", () => {
    expect(render().html).toMatchSnapshot();
  });
  test("recording: Stop recording, the file, duration, size and samples", () => {
    const { html } = render({ recording: status() });
    expect(html).toContain("rec.xdf · 12.3 s · 1.2 MB · 24\u202f600 samples");
    expect(html).toMatchSnapshot();
  });
  test("finished and failed recordings", () => {
    expect(render({ recording: status({ state: "finished" }) }).html).toMatchSnapshot();
    expect(
      render({ recording: status({ state: "failed", error: "disk full" }) }).html,
    ).toMatchSnapshot();
    expect(render({ recording: status({ state: "failed" }) }).html).toContain(" · failed: </span>");
  });
});

describe("RecordControl actions", () => {
  test("it follows the engine's recording status, and stops following", () => {
    const { log } = render();
    const cleanups = hooks.effects.map((fn) => fn());
    expect(log).toEqual([["onRecording", "function"]]);
    for (const c of cleanups) if (typeof c === "function") c();
    expect(log).toEqual([["onRecording", "function"], ["offRecording"]]);
  });
  test("Stop recording finishes the file and tells the engine's reply", async () => {
    const { log, elements } = render({ recording: status() });
    (the(elements, "button").onClick as () => void)();
    await settle();
    expect(log).toEqual([["recordStop"], ["notify", "stopped", "info"]]);
  });
  test("a failed stop is told as an error", async () => {
    const { log, elements } = render({
      recording: status(),
      reply: { ok: false, message: "no recording" } as Reply,
    });
    (the(elements, "button").onClick as () => void)();
    await settle();
    expect(log).toEqual([["recordStop"], ["notify", "no recording", "error"]]);
  });
});

describe("RecordControl dialog", () => {
  test("Record… opens it: the outputs with values, the acquisition ones picked, XDF", () => {
    openDialog();
    const { html } = render();
    expect(html).toContain('<dialog class="record-dialog"');
    expect(html).toContain("Written to recordings/ in the data folder");
    expect(html).toMatchSnapshot();
  });
  test("with the engine in the page the file is downloaded", () => {
    openDialog();
    const { html } = render({ engine: "browser (worker)" });
    expect(html).toContain("Kept in memory while it records, downloaded when you stop it.");
  });
  test("a pipeline without outputs: nothing to record, Start disabled", () => {
    openDialog();
    const { html } = render({ graph: { file: "p.yaml", blocks: [] } as unknown as GraphInfo });
    expect(html).toContain("<p>This pipeline has no output to record.</p>");
    expect(html).toMatchSnapshot();
  });
  test("it opens as a modal once mounted", () => {
    openDialog();
    const { elements } = render();
    const calls: string[] = [];
    (the(elements, "dialog").ref as { current: unknown }).current = {
      open: false,
      showModal: () => calls.push("showModal"),
    };
    for (const fn of hooks.effects) fn();
    expect(calls).toEqual(["showModal"]);
  });
  test("picking outputs and a format updates what is checked", () => {
    openDialog();
    const { elements } = render();
    hooks.updates.length = 0;
    const boxes = elements.filter(([t, p]) => t === "input" && p.type === "checkbox");
    expect(boxes.map(([, p]) => p.checked)).toEqual([true, true, false, false]);
    (boxes[0]![1].onChange as (e: unknown) => void)({ target: { checked: false } });
    (boxes[2]![1].onChange as (e: unknown) => void)({ target: { checked: true } });
    (the(elements, "input", (p) => p.value === "bdf").onChange as () => void)();
    expect(hooks.updates).toHaveLength(3);
    type Toggle = (s: Set<string>) => Set<string>;
    const [off, on, format] = hooks.updates as [Toggle, Toggle, string];
    const before = new Set(["Emg", "Emg.imu"]);
    expect([...off(before)]).toEqual(["Emg.imu"]);
    expect([...on(before)]).toEqual(["Emg", "Emg.imu", "Filter"]);
    expect([...before]).toEqual(["Emg", "Emg.imu"]);
    expect(format).toBe("bdf");
  });
  test("Start recording sends the picked outputs and format, and tells the reply", async () => {
    openDialog();
    const { log, elements } = render();
    const events: string[] = [];
    (the(elements, "form").onSubmit as (e: unknown) => void)({
      preventDefault: () => events.push("preventDefault"),
    });
    await settle();
    expect(events).toEqual(["preventDefault"]);
    expect(log).toEqual([
      [
        "recordStart",
        [
          { block: "Emg", port: "out" },
          { block: "Emg", port: "imu" },
        ],
        "xdf",
      ],
      ["notify", "recording to rec.xdf", "info"],
    ]);
  });
  test("nothing picked: Start disabled and does nothing", async () => {
    openDialog();
    const filterOnly = { file: "p.yaml", blocks: [graph.blocks[2]] } as unknown as GraphInfo;
    const { log, elements, html } = render({ graph: filterOnly });
    expect(html).not.toContain('type="checkbox" checked');
    expect(html).toContain('<button type="submit" class="primary" disabled="">');
    const events: string[] = [];
    (the(elements, "form").onSubmit as (e: unknown) => void)({
      preventDefault: () => events.push("preventDefault"),
    });
    await settle();
    expect(events).toEqual(["preventDefault"]);
    expect(log).toEqual([]);
  });
  test("the format picked is sent", async () => {
    openDialog();
    hooks.initial.set("xdf", "edf");
    const { log, elements, html } = render({ reply: { ok: false } as Reply });
    expect(html).toMatch(/checked="" value="edf"/);
    (the(elements, "form").onSubmit as (e: unknown) => void)({ preventDefault: () => {} });
    await settle();
    expect(log).toEqual([
      [
        "recordStart",
        [
          { block: "Emg", port: "out" },
          { block: "Emg", port: "imu" },
        ],
        "edf",
      ],
      ["notify", "recording", "error"],
    ]);
  });
  test("Cancel, Escape and closing the dialog all close it (the same handler)", () => {
    openDialog();
    const { elements } = render();
    const dialog = the(elements, "dialog");
    const cancel = the(elements, "button", (p) => p.type === "button" && p.className === undefined);
    expect(typeof dialog.onClose).toBe("function");
    expect(dialog.onCancel).toBe(dialog.onClose);
    expect(cancel.onClick).toBe(dialog.onClose);
  });
});
