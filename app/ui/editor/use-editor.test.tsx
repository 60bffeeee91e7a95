import { afterEach, beforeEach, describe, expect, it, vi } from "vitest";

/**
 * A minimal stand-in for React's hook dispatcher (no DOM here): state, refs and memos live in
 * slots by call order, as in React; a state update takes effect at the next `render`. It records
 * which hooks each render called, in order.
 */
const fake = vi.hoisted(() => {
  const slots: unknown[] = [];
  const state = { index: 0, calls: [] as string[] };
  const slot = <T,>(kind: string, init: () => T): { k: number; fresh: boolean } => {
    state.calls.push(kind);
    const k = state.index++;
    const fresh = !(k in slots);
    if (fresh) slots[k] = init();
    return { k, fresh };
  };
  const sameDeps = (a: readonly unknown[], b: readonly unknown[]): boolean =>
    a.length === b.length && a.every((x, i) => Object.is(x, b[i]));
  const memo = <T,>(kind: string, make: () => T, deps: readonly unknown[]): T => {
    const { k, fresh } = slot(kind, () => ({ value: make(), deps }));
    const m = slots[k] as { value: T; deps: readonly unknown[] };
    if (!fresh && !sameDeps(m.deps, deps)) slots[k] = { value: make(), deps };
    return (slots[k] as { value: T }).value;
  };
  return {
    slots,
    state,
    react: {
      useState: <T,>(init: T) => {
        // As React's, the setter is the same function on every render.
        const { k } = slot("useState", () => {
          const cell = { value: init, set: (v: T) => void (cell.value = v) };
          return cell;
        });
        const cell = slots[k] as { value: T; set: (v: T) => void };
        return [cell.value, cell.set];
      },
      useRef: <T,>(init: T) => slots[slot("useRef", () => ({ current: init })).k],
      useMemo: <T,>(make: () => T, deps: readonly unknown[]) => memo("useMemo", make, deps),
      useCallback: <T,>(f: T, deps: readonly unknown[]) => memo("useCallback", () => f, deps),
    },
  };
});

vi.mock("react", () => fake.react);

const { useEditor } = await import("./use-editor");

const TEXT = "T: { Type: Tick }\nG: { Type: Gain, Inputs: [T] }\n";
const BROKEN = "T: { Type: Tick\n";

function render(text = TEXT, file = "p.yaml") {
  fake.state.index = 0;
  fake.state.calls = [];
  return useEditor(text, file);
}

let now = 10_000;

beforeEach(() => {
  fake.slots.length = 0;
  now = 10_000;
  vi.spyOn(Date, "now").mockImplementation(() => now);
});

afterEach(() => {
  vi.restoreAllMocks();
});

describe("useEditor", () => {
  it("starts with the text, its blocks and no history", () => {
    const m = render();
    expect(m).toMatchObject({ text: TEXT, file: "p.yaml", broken: false });
    expect(m.blocks.map((b) => b.name)).toEqual(["T", "G"]);
    expect(m.canUndo).toBe(false);
    expect(m.canRedo).toBe(false);
    expect(m.textNow()).toBe(TEXT);
    expect(Object.keys(m)).toEqual([
      "text",
      "file",
      "blocks",
      "broken",
      "canUndo",
      "canRedo",
      "edit",
      "setText",
      "reset",
      "undo",
      "redo",
      "freshName",
      "textNow",
    ]);
  });

  it("calls the same hooks in the same order on every render; callbacks keep their identity", () => {
    const order = [
      "useState",
      "useRef",
      "useRef",
      "useCallback",
      "useCallback",
      "useCallback",
      "useCallback",
      "useCallback",
      "useCallback",
      "useRef",
      "useMemo",
      "useCallback",
    ];
    const first = render();
    expect(fake.state.calls).toEqual(order);
    first.setText(BROKEN);
    const second = render();
    expect(fake.state.calls).toEqual(order);
    for (const k of ["edit", "setText", "reset", "undo", "redo", "freshName"] as const) {
      expect(second[k]).toBe(first[k]);
    }
  });

  it("typing within 800 ms is one undo step; later typing is another", () => {
    const m = render();
    m.setText(`${TEXT}# a\n`);
    now += 500;
    m.setText(`${TEXT}# ab\n`);
    now += 800;
    m.setText(`${TEXT}# abc\n`);
    expect(m.textNow()).toBe(`${TEXT}# abc\n`);
    expect(render().canUndo).toBe(true);
    m.undo();
    expect(m.textNow()).toBe(`${TEXT}# ab\n`);
    m.undo();
    expect(m.textNow()).toBe(TEXT);
    const back = render();
    expect(back).toMatchObject({ text: TEXT, canUndo: false, canRedo: true });
    m.undo(); // nothing left: no change
    expect(m.textNow()).toBe(TEXT);
    m.redo();
    m.redo();
    m.redo(); // nothing left: no change
    expect(render()).toMatchObject({ text: `${TEXT}# abc\n`, canUndo: true, canRedo: false });
  });

  it("the same text and file again is no step; a new text clears the redo list", () => {
    const m = render();
    m.setText(TEXT);
    expect(render().canUndo).toBe(false);
    m.setText(`${TEXT}# x\n`);
    m.undo();
    expect(render().canRedo).toBe(true);
    now += 100;
    m.setText(`${TEXT}# y\n`);
    expect(render()).toMatchObject({ text: `${TEXT}# y\n`, canUndo: true, canRedo: false });
  });

  it("edit applies a document operation as its own step, or returns why it was refused", () => {
    const m = render();
    m.setText(`${TEXT}# a\n`);
    expect(m.edit((doc) => doc.addBlock("D", "Drain", { inputs: ["G"] }))).toBeUndefined();
    const edited = m.textNow();
    expect(edited).toContain("D:");
    // Typing right after an edit is not merged into the edit's step.
    m.setText(`${edited}# b\n`);
    m.undo();
    expect(m.textNow()).toBe(edited);
    expect(m.edit((doc) => doc.removeBlock("Nope"))).toBe("no block 'Nope'");
    expect(m.textNow()).toBe(edited);
  });

  it("reset starts over with another text and file, undoably", () => {
    const m = render();
    m.reset("A: { Type: Tick }\n", "other.yaml");
    expect(render()).toMatchObject({ text: "A: { Type: Tick }\n", file: "other.yaml" });
    m.undo();
    expect(render()).toMatchObject({ text: TEXT, file: "p.yaml", canRedo: true });
  });

  it("a text that does not parse is broken and keeps the last blocks that did", () => {
    const m = render();
    m.setText(BROKEN);
    const b = render();
    expect(b.broken).toBe(true);
    expect(b.text).toBe(BROKEN);
    expect(b.blocks.map((x) => x.name)).toEqual(["T", "G"]);
  });

  it("freshName asks the document, or the names read when the text does not parse", () => {
    const m = render();
    expect(m.freshName("T")).toBe("T2");
    expect(m.freshName("my block")).toBe("my_block");
    m.setText(BROKEN);
    expect(m.freshName("my block")).toBe("my block");
    expect(m.freshName("T")).toBe("T");
  });
});
