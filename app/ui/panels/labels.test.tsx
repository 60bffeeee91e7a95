import { createElement } from "react";
import { renderToStaticMarkup } from "react-dom/server";
import { afterEach, describe, expect, test, vi } from "vitest";
import type { BlockInfo, DataMessage } from "../../engine/protocol";
import type { Telemetry } from "../../engine/runtime/runtime";
import type { EngineClient } from "../client/engine-client";
import { EngineContext } from "../client/hooks";
import { clearHooks, hooks } from "../test-support/jsx-spy";
import { LABELS_MAX, LabelDisplay } from "./labels";

/**
 * What the test sees of the hooks: the data each watched output gets at once (delivered while it
 * renders), every watch asked for and every frame task (effects and state updates: jsx-spy's
 * `hooks`).
 */
const spy = vi.hoisted(() => ({
  feed: new Map<string, Partial<DataMessage>[]>(),
  watches: [] as unknown[][],
  frames: [] as ((now: number) => void)[],
  log: [] as unknown[],
}));
vi.mock("react", async (orig) =>
  (await import("../test-support/jsx-spy")).spyReact(await orig<typeof import("react")>()),
);
vi.mock("../client/hooks", async (orig) => {
  const m = await orig<typeof import("../client/hooks")>();
  return {
    ...m,
    useBlockData: (
      block: string,
      port: string | undefined,
      onData: (d: DataMessage) => void,
      active?: boolean,
      maxRate?: number,
    ) => {
      spy.watches.push([block, port, active, maxRate]);
      for (const d of spy.feed.get(`${block}.${port}`) ?? []) onData(d as DataMessage);
    },
  };
});
vi.mock("./frame", () => ({
  onFrame: (fn: (now: number) => void) => {
    spy.frames.push(fn);
    return () => spy.log.push("frame task removed");
  },
}));
afterEach(() => {
  spy.feed.clear();
  spy.watches.length = 0;
  clearHooks();
  spy.frames.length = 0;
  spy.log.length = 0;
});

type Output = { name: string; shape: { rows: number; cols: number }; labels?: string[] };

const block = (outputs: Output[]): BlockInfo =>
  ({ name: "Lda", type: "Lda", outputs }) as unknown as BlockInfo;

const data = (t: number[], v: number[], skipped = 0): Partial<DataMessage> => ({
  t: Float64Array.from(t),
  v: Float64Array.from(v),
  skipped,
});

/** The label display's markup for a block; `text` is the block's status text in telemetry. */
function render(b: BlockInfo, active = true, text?: string): string {
  const telemetry =
    text === undefined ? undefined : ({ blocks: [{ name: b.name, text }] } as unknown as Telemetry);
  const client = { telemetry, onTelemetry: () => () => {} } as unknown as EngineClient;
  return renderToStaticMarkup(
    createElement(
      EngineContext.Provider,
      { value: client },
      createElement(LabelDisplay, { block: b, active }),
    ),
  );
}

describe("LabelDisplay markup", () => {
  test("no data yet, watched and hidden, and no status text", () => {
    const b = block([{ name: "out", shape: { rows: 1, cols: 3 } }]);
    expect(render(b, true)).toContain("waiting for data…");
    expect(render(b, false)).toContain("hidden: no data is watched");
    expect(render(b, true)).toMatchSnapshot();
    expect(spy.watches).toEqual([
      ["Lda", "out", true, 20],
      ["Lda", "out", false, 20],
      ["Lda", "out", true, 20],
    ]);
  });
  test("the latest event's values by channel label, and the status text", () => {
    spy.feed.set("Lda.out", [
      data([1, 2], [1, 2, 3, 4, 5, 6]),
      data([3, 4], [0.5, -0.25, 1e7, 7, 8, 9]),
      data([], []),
    ]);
    const html = render(
      block([{ name: "out", shape: { rows: 1, cols: 3 }, labels: ["rest", "fist"] }]),
      true,
      "trained on 340 samples",
    );
    expect(html).toContain("<dt>rest</dt><dd>7.000</dd>");
    expect(html).toContain("<dt>2</dt><dd>9.000</dd>");
    expect(html).toMatchSnapshot();
  });
  test("a matrix output lists its values by [row, col]", () => {
    spy.feed.set("Lda.m", [data([1], [1, 2, 3, 4, 5, 6])]);
    const html = render(block([{ name: "m", shape: { rows: 2, cols: 3 } }]));
    expect(html).toContain("<dt>[1, 2]</dt><dd>6.000</dd>");
    expect(html).toMatchSnapshot();
  });
  test("more values than listed: a summary of all and the first ones", () => {
    const n = LABELS_MAX + 6;
    spy.feed.set("Lda.big", [
      data(
        [1],
        Array.from({ length: n }, (_x, i) => i - 3),
      ),
    ]);
    const html = render(block([{ name: "big", shape: { rows: 1, cols: n } }]));
    expect(html).toContain(`all ${n}: min −3.000, mean 31.50, max 66.00`);
    expect(html.match(/class="mp-value"/g)).toHaveLength(LABELS_MAX);
    expect(html).toMatchSnapshot();
  });
  test("a timer's output: ticks seen (skipped ones counted), or none yet", () => {
    const timer = block([{ name: "tick", shape: { rows: 0, cols: 0 } }]);
    expect(render(timer)).toContain("events without values (a timer): no tick seen yet");
    spy.feed.set("Lda.tick", [data([1, 2], [], 3), data([3], [], 1)]);
    const html = render(timer);
    expect(html).toContain("events without values (a timer): 7 ticks seen");
    expect(html).toMatchSnapshot();
  });
  test("several outputs in order", () => {
    spy.feed.set("Lda.b", [data([1], [4])]);
    expect(
      render(
        block([
          { name: "a", shape: { rows: 1, cols: 1 } },
          { name: "b", shape: { rows: 1, cols: 1 } },
        ]),
      ),
    ).toMatchSnapshot();
  });
});

describe("LabelDisplay refresh", () => {
  test("new data shows at most every 200 ms, on an animation frame", () => {
    spy.feed.set("Lda.out", [data([1], [1])]);
    render(block([{ name: "out", shape: { rows: 1, cols: 1 } }]));
    const cleanups = hooks.effects.map((fn) => fn());
    expect(spy.frames).toHaveLength(1);
    const frame = spy.frames[0]!;
    frame(100);
    expect(hooks.updates).toHaveLength(0);
    frame(250);
    expect(hooks.updates).toHaveLength(1);
    expect((hooks.updates[0] as (x: number) => number)(4)).toBe(5);
    frame(500);
    expect(hooks.updates).toHaveLength(1);
    for (const c of cleanups) if (typeof c === "function") c();
    expect(spy.log).toEqual(["frame task removed"]);
  });
  test("hidden: no frame task", () => {
    render(block([{ name: "out", shape: { rows: 1, cols: 1 } }]), false);
    for (const fn of hooks.effects) expect(fn()).toBeUndefined();
    expect(spy.frames).toHaveLength(0);
  });
});
