/**
 * Find a block by name on the BlockTable (issue 17, "large flows"): a search field (Ctrl+F while
 * the pointer or the focus is on the graph). Every block whose name contains the text is
 * outlined; Enter centres the next one (Shift+Enter the one before), Escape clears.
 */
import { useReactFlow, type ReactFlowInstance } from "@xyflow/react";
import { useEffect, useMemo, useRef, useState } from "react";
import { matchingNames } from "./find";

/** Outlines of the matches (block names are plain words: safe inside a CSS string). */
function highlightCss(matches: readonly string[], current: string | undefined): string {
  const sel = (n: string) => `.block-table .react-flow__node[data-id="${n}"]`;
  const all = matches.map(sel).join(",\n");
  return (
    (all ? `${all} { outline: 3px solid #f5a623; outline-offset: 3px; }\n` : "") +
    (current ? `${sel(current)} { outline: 4px solid #d35400; outline-offset: 3px; }\n` : "")
  );
}

/** Ctrl+F (⌘F) focuses `input` while the pointer or the focus is inside its graph. */
function useFindKey(input: React.RefObject<HTMLInputElement | null>): void {
  useEffect(() => {
    const onKey = (e: KeyboardEvent): void => {
      if (!(e.ctrlKey || e.metaKey) || e.altKey || e.key.toLowerCase() !== "f") return;
      const el = input.current;
      const graph = el?.closest(".block-table");
      if (!el || !graph) return;
      if (!graph.matches(":hover") && !graph.contains(document.activeElement)) return;
      e.preventDefault();
      el.focus();
      el.select();
    };
    window.addEventListener("keydown", onKey);
    return () => window.removeEventListener("keydown", onKey);
  }, [input]);
}

const frame = (): Promise<void> => new Promise((r) => requestAnimationFrame(() => r()));

/**
 * Centres block `id` at zoom ≥ 1. Its text scales with the zoom (readable-zoom.ts), so its size
 * may change on the way: it is measured again once there and the view corrected (twice at most).
 */
async function centreOn(flow: ReactFlowInstance, id: string, duration: number): Promise<void> {
  let last: { x: number; y: number } | undefined;
  for (let pass = 0; pass < 3; pass++) {
    const node = flow.getInternalNode(id);
    if (!node) return;
    const p = node.internals.positionAbsolute;
    const c = { x: p.x + (node.measured.width ?? 0) / 2, y: p.y + (node.measured.height ?? 0) / 2 };
    if (last && Math.abs(c.x - last.x) < 0.5 && Math.abs(c.y - last.y) < 0.5) return;
    last = c;
    const zoom = Math.max(flow.getZoom(), 1);
    await flow.setCenter(c.x, c.y, { zoom, duration: pass === 0 ? duration : 0 });
    await frame();
    await frame();
  }
}

export function BlockSearch({ names, duration }: { names: readonly string[]; duration: number }) {
  const flow = useReactFlow();
  const input = useRef<HTMLInputElement>(null);
  const [query, setQuery] = useState("");
  const [at, setAt] = useState(-1);
  const matches = useMemo(() => matchingNames(names, query), [names, query]);
  const current = at >= 0 ? matches[at] : undefined;
  useFindKey(input);

  const centre = (step: number): void => {
    if (matches.length === 0) return;
    const next = (at + step + matches.length) % matches.length;
    setAt(next);
    void centreOn(flow, matches[next]!, duration);
  };
  const onKeyDown = (e: React.KeyboardEvent<HTMLInputElement>): void => {
    if (e.key === "Enter") centre(e.shiftKey ? -1 : 1);
    else if (e.key === "Escape") {
      setQuery("");
      setAt(-1);
      input.current?.blur();
    } else return;
    e.preventDefault();
  };

  const count =
    query.trim() === ""
      ? ""
      : matches.length === 0
        ? "no block"
        : `${at >= 0 ? `${at + 1} of ` : ""}${matches.length}`;
  return (
    <div className="block-search" data-matches={matches.join(",")} data-current={current ?? ""}>
      <input
        ref={input}
        type="search"
        value={query}
        placeholder="Find a block (Ctrl+F)"
        aria-label="Find a block by name: Enter centres the next match"
        onChange={(e) => {
          setQuery(e.target.value);
          setAt(-1);
        }}
        onKeyDown={onKeyDown}
      />
      <span className="block-search__count" aria-live="polite">
        {count}
      </span>
      <style>{highlightCss(matches, current)}</style>
    </div>
  );
}
