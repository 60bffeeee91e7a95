/**
 * The palette of block types (from the engine's catalog): searchable, grouped by category, with
 * the summary on each entry and the help text on demand. Drag an entry onto the canvas, or
 * focus it and press Enter to add it next to the others.
 */
import { useId, useMemo, useState, type ReactNode } from "react";
import type { BlockTypeInfo, CatalogInfo } from "../../engine/protocol";

/** The drag-and-drop data type of a palette entry (its value: the block type). */
export const BLOCK_TYPE_MIME = "application/x-mosaic-block-type";

export function Palette({
  catalog,
  onAdd,
}: {
  catalog: CatalogInfo | undefined;
  onAdd(type: string): void;
}): ReactNode {
  const [query, setQuery] = useState("");
  const [help, setHelp] = useState<string | null>(null);
  const searchId = useId();
  const groups = useMemo(() => {
    const q = query.trim().toLowerCase();
    const m = new Map<string, BlockTypeInfo[]>();
    for (const t of catalog?.types ?? []) {
      const hay = `${t.type} ${t.aliases.join(" ")} ${t.category} ${t.summary}`.toLowerCase();
      if (q !== "" && !q.split(/\s+/).every((w) => hay.includes(w))) continue;
      m.set(t.category, [...(m.get(t.category) ?? []), t]);
    }
    return [...m];
  }, [catalog, query]);

  return (
    <aside className="palette" aria-label="Block palette">
      <label className="palette__search" htmlFor={searchId}>
        <span className="sr-only">Search block types</span>
        <input
          id={searchId}
          type="search"
          placeholder="Search blocks…"
          value={query}
          onChange={(e) => setQuery(e.target.value)}
        />
      </label>
      {catalog === undefined ? <p className="palette__empty">Loading the catalog…</p> : null}
      {catalog !== undefined && groups.length === 0 ? (
        <p className="palette__empty">No block type matches “{query}”.</p>
      ) : null}
      <div className="palette__groups">
        {groups.map(([category, types]) => (
          <section key={category} className="palette__group" aria-label={category}>
            <h3 className="palette__category">{category}</h3>
            <ul>
              {types.map((t) => (
                <li key={t.type}>
                  <div
                    className="palette__item"
                    role="button"
                    tabIndex={0}
                    draggable
                    data-block-type={t.type}
                    aria-label={`${t.type}: ${t.summary}. Enter: add to the pipeline`}
                    title={`${t.summary}\nDrag onto the canvas, or Enter to add`}
                    onDragStart={(e) => {
                      e.dataTransfer.setData(BLOCK_TYPE_MIME, t.type);
                      e.dataTransfer.setData("text/plain", t.type);
                      e.dataTransfer.effectAllowed = "copy";
                    }}
                    onKeyDown={(e) => {
                      if (e.key === "Enter" || e.key === " ") {
                        e.preventDefault();
                        onAdd(t.type);
                      }
                    }}
                    onDoubleClick={() => onAdd(t.type)}
                  >
                    <span className="palette__type">{t.type}</span>
                    <span className="palette__summary">{t.summary}</span>
                  </div>
                  <button
                    type="button"
                    className="palette__help-toggle"
                    aria-expanded={help === t.type}
                    aria-label={`Help on ${t.type}`}
                    onClick={() => setHelp((h) => (h === t.type ? null : t.type))}
                  >
                    ?
                  </button>
                  {help === t.type ? <p className="palette__help">{t.help}</p> : null}
                </li>
              ))}
            </ul>
          </section>
        ))}
      </div>
    </aside>
  );
}
