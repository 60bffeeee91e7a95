import { describe, expect, test } from "vitest";
import {
  panelsFor,
  parseLayout,
  readLayout,
  restoreSettings,
  storageKey,
  writeLayout,
  type KeyValueStore,
  type SavedPanel,
} from "./panel-layouts";

/** A store in memory (the browser's localStorage has the same three methods used here). */
function memoryStorage(): KeyValueStore & { data: Map<string, string> } {
  const data = new Map<string, string>();
  return {
    data,
    getItem: (k: string) => data.get(k) ?? null,
    removeItem: (k: string) => void data.delete(k),
    setItem: (k: string, v: string) => void data.set(k, v),
  };
}

const scope: SavedPanel = {
  name: "Emg",
  type: "EmgSimulator",
  floating: false,
  collapsed: false,
  x: 60,
  y: 40,
  view: { tab: "scope", port: "out", settings: { scope: { channels: [0, 3], windowS: 10 } } },
};
const floating: SavedPanel = {
  name: "LowPass",
  type: "Filter",
  floating: true,
  collapsed: true,
  x: 300,
  y: 120,
  width: 520,
  height: 400,
};

describe("saved panel layouts", () => {
  test("written and read back per pipeline file; none for another file", () => {
    const s = memoryStorage();
    writeLayout(s, "pipelines/demo.yaml", [scope, floating]);
    expect(readLayout(s, "pipelines/demo.yaml")).toEqual({
      version: 1,
      panels: [scope, floating],
    });
    expect(readLayout(s, "pipelines/examples/training.yaml")).toBeUndefined();
    expect([...s.data.keys()]).toEqual([storageKey("pipelines/demo.yaml")]);
  });

  test("closing every panel forgets the layout", () => {
    const s = memoryStorage();
    writeLayout(s, "a.yaml", [scope]);
    writeLayout(s, "a.yaml", []);
    expect(s.data.size).toBe(0);
  });

  test("panels come back only on blocks of the same name and type, in saved order", () => {
    const layout = { version: 1 as const, panels: [scope, floating] };
    const blocks = new Map([
      ["LowPass", { type: "Filter" }],
      ["Emg", { type: "Myo" }],
    ]);
    expect(panelsFor(layout, blocks)).toEqual([floating]);
    expect(panelsFor(undefined, blocks)).toEqual([]);
  });

  test("what is not a layout is ignored, and bad fields dropped", () => {
    expect(parseLayout(null)).toBeUndefined();
    expect(parseLayout("{")).toBeUndefined();
    expect(parseLayout('{"version":2,"panels":[]}')).toBeUndefined();
    const text = JSON.stringify({
      version: 1,
      panels: [
        {
          name: "A",
          type: "T",
          x: 1,
          y: 2,
          width: -5,
          view: { tab: 3, settings: { scope: { f: {} } } },
        },
        { name: "B", type: "T", x: "1", y: 2 },
        "junk",
      ],
    });
    expect(parseLayout(text)).toEqual({
      version: 1,
      panels: [
        {
          name: "A",
          type: "T",
          floating: false,
          collapsed: false,
          x: 1,
          y: 2,
          view: { settings: { scope: {} } },
        },
      ],
    });
  });

  test("a storage that refuses (privacy settings) keeps nothing and breaks nothing", () => {
    const refusing = memoryStorage();
    refusing.setItem = () => {
      throw new Error("QuotaExceededError");
    };
    refusing.getItem = () => {
      throw new Error("SecurityError");
    };
    expect(() => writeLayout(refusing, "a.yaml", [scope])).not.toThrow();
    expect(readLayout(refusing, "a.yaml")).toBeUndefined();
  });
});

describe("view settings restored over the defaults", () => {
  const defaults = {
    windowS: 5,
    yMode: "auto",
    paused: false,
    channels: undefined as number[] | undefined,
  };
  test("saved values of the default's kind win; others are dropped", () => {
    expect(
      restoreSettings(defaults, { windowS: 30, yMode: 7, channels: [1, 2], extra: { a: 1 } }),
    ).toEqual({ windowS: 30, yMode: "auto", paused: false, channels: [1, 2] });
    expect(restoreSettings(defaults, undefined)).toBe(defaults);
  });
});
