import { createElement } from "react";
import { renderToStaticMarkup } from "react-dom/server";
import { afterEach, describe, expect, test, vi } from "vitest";
import type { Reply } from "../client/engine-client";
import type { EngineClient } from "../client/engine-client";
import { EngineContext } from "../client/hooks";
import { created, withHandler } from "../test-support/jsx-spy";
import { OpenLocal } from "./open-local";

vi.mock("react/jsx-runtime", async (orig) =>
  (await import("../test-support/jsx-spy")).spyJsx(await orig<object>()),
);
vi.mock("react/jsx-dev-runtime", async (orig) =>
  (await import("../test-support/jsx-spy")).spyJsx(await orig<object>()),
);
afterEach(() => {
  created.length = 0;
});

/** Renders OpenLocal; `log` gets every call to the engine, onOpen and notify, in order. */
function render(inPage: boolean, reply: Reply = { ok: true } as Reply) {
  const log: unknown[][] = [];
  const client = {
    openedLocally: (file: string, urls: Record<string, string>) =>
      log.push(["openedLocally", file, Object.keys(urls)]),
  } as unknown as EngineClient;
  const onOpen = (file: string, text: string) => {
    log.push(["onOpen", file, text]);
    return Promise.resolve(reply);
  };
  const notify = (message: string, level?: string) => log.push(["notify", message, level]);
  const html = renderToStaticMarkup(
    createElement(
      EngineContext.Provider,
      { value: client },
      createElement(OpenLocal, { inPage, onOpen, notify }),
    ),
  );
  return { html, log, input: withHandler("onChange") };
}

const file = (path: string, text: string): File => {
  const f = new File([text], path.split("/").pop()!);
  Object.defineProperty(f, "webkitRelativePath", { value: path });
  return f;
};
const change = (files: File[] | null) => ({ target: { files, value: "picked" } });
const settle = () => new Promise((r) => setTimeout(r, 20));

describe("OpenLocal markup", () => {
  test("with the engine in the page: open file and open folder", () => {
    expect(render(true).html).toMatchSnapshot();
  });
  test("with a remote engine: open file only", () => {
    const { html, input } = render(false);
    expect(html).not.toContain("folder-open");
    expect(input).toHaveLength(1);
    expect(html).toMatchSnapshot();
  });
});

describe("OpenLocal opens a file", () => {
  test("in the page: the engine is told, then the text opens; the input is cleared", async () => {
    const { log, input } = render(true);
    const e = change([file("p.yaml", "blocks: {}")]);
    input[0]!.onChange(e);
    expect(e.target.value).toBe("");
    await settle();
    expect(log).toEqual([
      ["openedLocally", "p.yaml", []],
      ["onOpen", "p.yaml", "blocks: {}"],
    ]);
  });
  test("a remote engine is not told", async () => {
    const { log, input } = render(false);
    input[0]!.onChange(change([file("p.yaml", "x")]));
    await settle();
    expect(log).toEqual([["onOpen", "p.yaml", "x"]]);
  });
  test("nothing picked: nothing opened", async () => {
    const { log, input } = render(true);
    const e = change([]);
    input[0]!.onChange(e);
    expect(e.target.value).toBe("");
    await settle();
    expect(log).toEqual([]);
  });
});

describe("OpenLocal opens a folder", () => {
  test("one pipeline: left-out files are said, then it opens with the folder's files", async () => {
    const { log, input } = render(true);
    const e = change([
      file("d/a.yaml", "A"),
      file("d/.git/config", "g"),
      file("d/node_modules/x.yaml", "n"),
      file("d/data.csv", "1,2"),
    ]);
    input[1]!.onChange(e);
    expect(e.target.value).toBe("");
    await settle();
    expect(log).toEqual([
      ["notify", "d: 2 files left out (hidden, node_modules or too many)", undefined],
      ["openedLocally", "d/a.yaml", ["d/a.yaml", "d/data.csv"]],
      ["onOpen", "d/a.yaml", "A"],
    ]);
  });
  test("no pipeline in it: an error", async () => {
    const { log, input } = render(true);
    input[1]!.onChange(change([file("d/data.csv", "1")]));
    await settle();
    expect(log).toEqual([["notify", "No pipeline (.yaml) in the folder d", "error"]]);
  });
  test("several pipelines: none is opened (the page asks which)", async () => {
    const { log, input } = render(true);
    input[1]!.onChange(change([file("d/b.yml", "B"), file("d/a.yaml", "A")]));
    await settle();
    expect(log).toEqual([]);
  });
  test("an empty pick: nothing happens and the input keeps its value", async () => {
    const { log, input } = render(true);
    const e = change([]);
    input[1]!.onChange(e);
    expect(e.target.value).toBe("picked");
    await settle();
    expect(log).toEqual([]);
  });
});
