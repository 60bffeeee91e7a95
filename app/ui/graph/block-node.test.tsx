import { ReactFlowProvider } from "@xyflow/react";
import { createElement, type ComponentType } from "react";
import { renderToStaticMarkup } from "react-dom/server";
import { afterEach, describe, expect, test, vi } from "vitest";
import type { BlockInfo } from "../../engine/protocol";
import type { Telemetry } from "../../engine/runtime/runtime";
import type { EngineClient } from "../client/engine-client";
import { EngineContext } from "../client/hooks";
import { created, withHandler } from "../test-support/jsx-spy";
import { BlockNode as RealBlockNode, GraphStateContext, type GraphState } from "./block-node";

vi.mock("react/jsx-runtime", async (orig) =>
  (await import("../test-support/jsx-spy")).spyJsx(await orig<object>()),
);
vi.mock("react/jsx-dev-runtime", async (orig) =>
  (await import("../test-support/jsx-spy")).spyJsx(await orig<object>()),
);
afterEach(() => {
  created.length = 0;
});

/** The node's props as the tests give them (React Flow passes many more, which it does not read). */
type NodeProps = { data: { block: BlockInfo; edit?: { issues: string[] } } };
const BlockNode = RealBlockNode as unknown as ComponentType<NodeProps>;

const block = (over: Partial<BlockInfo> = {}): BlockInfo =>
  ({
    name: "Filter",
    type: "Bandpass",
    summary: "",
    desiredRate: 250,
    inputs: [{ block: "Src", port: "out" }],
    live: ["low"],
    params: { low: 1 },
    fileParams: { low: 1 },
    ...over,
  }) as unknown as BlockInfo;

const stats = (over: Record<string, unknown> = {}) => ({
  name: "Filter",
  status: "ontime",
  stumbling: false,
  rate: 24.96,
  text: "",
  errors: 0,
  lastError: "",
  dropsIn: 0,
  computeMeanMs: 0,
  ...over,
});

/** The node's markup for a block, its telemetry, the graph state and the edit data. */
function render(
  b: BlockInfo,
  opts: {
    telemetry?: Record<string, unknown>;
    running?: boolean;
    open?: boolean;
    edit?: { issues: string[] };
    onMenu?: GraphState["onMenu"];
  } = {},
): string {
  const telemetry = opts.telemetry
    ? ({ blocks: [opts.telemetry] } as unknown as Telemetry)
    : undefined;
  const client = {
    telemetry,
    graph: undefined,
    onTelemetry: () => () => {},
    onParams: () => () => {},
  } as unknown as EngineClient;
  const graph = {
    running: opts.running ?? true,
    openPanels: new Set(opts.open ? [b.name] : []),
    onMenu: opts.onMenu ?? (() => {}),
  };
  const props: NodeProps = { data: { block: b, edit: opts.edit } };
  return renderToStaticMarkup(
    createElement(
      ReactFlowProvider,
      null,
      createElement(
        EngineContext.Provider,
        { value: client },
        createElement(
          GraphStateContext.Provider,
          { value: graph },
          createElement(BlockNode, props),
        ),
      ),
    ),
  );
}

describe("BlockNode markup", () => {
  test("no telemetry: idle, no rate, no text", () => {
    expect(render(block({ inputs: [] }))).toMatchSnapshot();
  });
  test("running, on time, a fractional desired rate, compute time and a summary", () => {
    const html = render(block({ desiredRate: 12.5, summary: "keeps 1–40 Hz" }), {
      telemetry: stats({ computeMeanMs: 0.01234 }),
      open: true,
    });
    expect(html).toContain('class="block-node status-ontime panel-open"');
    expect(html).toMatchSnapshot();
  });
  test("lagging and stumbling, errors, drops, a changed live value", () => {
    const html = render(block({ params: { low: 2 } }), {
      telemetry: stats({
        status: "lagging",
        stumbling: true,
        text: "t",
        errors: 2,
        lastError: "boom",
        dropsIn: 3,
      }),
    });
    expect(html).toContain("also-stumbling has-errors");
    expect(html).toContain("2 errors");
    expect(html).toMatchSnapshot();
  });
  test("one error, text only, not running", () => {
    expect(
      render(block(), {
        telemetry: stats({ status: "lagging", text: "note", errors: 1, lastError: "e" }),
        running: false,
      }),
    ).toMatchSnapshot();
  });
  test("edit mode with and without issues", () => {
    expect(render(block({ summary: "s" }), { edit: { issues: ["a", "b"] } })).toMatchSnapshot();
    expect(render(block(), { edit: { issues: [] }, telemetry: stats() })).toMatchSnapshot();
  });
  test("the menu button opens the block's actions below itself, and the click stops there", () => {
    const log: unknown[] = [];
    render(block(), { onMenu: (name, at) => log.push(["menu", name, at]) });
    const clicks = withHandler("onClick");
    expect(clicks).toHaveLength(1);
    clicks[0]!.onClick({
      stopPropagation: () => log.push(["stop"]),
      currentTarget: { getBoundingClientRect: () => ({ left: 10, bottom: 40 }) },
    });
    expect(log).toEqual([["stop"], ["menu", "Filter", { x: 10, y: 42 }]]);
  });
  test("in edit mode there is no menu button", () => {
    render(block(), { edit: { issues: [] } });
    expect(withHandler("onClick")).toHaveLength(0);
  });
});
