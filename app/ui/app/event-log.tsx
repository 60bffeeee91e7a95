/**
 * The log of the current load: its diagnostics, then runtime events (errors and warnings per
 * block) and the replies to actions; the counts beside it are this load's (./log-book.ts), so
 * they match the list and start again with every load. Earlier loads are kept, folded away.
 * _Download_ saves the whole log (every load kept) as a JSON Lines file.
 */
import { memo } from "react";
import {
  countsText,
  currentCounts,
  currentEntries,
  earlierEntries,
  logFileName,
  logJsonLines,
  type LogBook,
  type LogEntry,
} from "./log-book";
import { saveFile } from "./save-file";

export type { LogEntry } from "./log-book";

const time = (t: number): string => {
  const d = new Date(t * 1000);
  const p = (n: number, w = 2) => String(n).padStart(w, "0");
  return `${p(d.getHours())}:${p(d.getMinutes())}:${p(d.getSeconds())}`;
};

const LEVEL_MARK: Record<LogEntry["level"], string> = { error: "✖", warning: "▲", info: "●" };

function Entry({ e }: { e: LogEntry }) {
  return (
    <li className={`event-log__entry level-${e.level}`} data-level={e.level}>
      <span className="event-log__mark" aria-hidden="true">
        {LEVEL_MARK[e.level]}
      </span>
      <time>{time(e.t)}</time>
      <span className="event-log__level">{e.level}</span>
      {e.block ? <strong className="event-log__block">{e.block}</strong> : null}
      <span className="event-log__message">{e.message}</span>
    </li>
  );
}

function Counts({ book }: { book: LogBook }) {
  const c = currentCounts(book);
  return (
    <span
      className="event-log__counts"
      data-errors={c.errors}
      data-warnings={c.warnings}
      title="Since the pipeline was loaded"
    >
      {c.errors > 0 || c.warnings > 0 ? (
        <>
          {c.errors > 0 ? (
            <span className="count-error">{countsText({ ...c, warnings: 0 })}</span>
          ) : null}
          {c.warnings > 0 ? (
            <span className="count-warning">{countsText({ ...c, errors: 0 })}</span>
          ) : null}
        </>
      ) : (
        <span>{countsText(c)}</span>
      )}
    </span>
  );
}

/** Saves the log as mosaic-log-DATE-TIME.jsonl through the browser's download. */
function downloadLog(book: LogBook): void {
  const bytes = new TextEncoder().encode(logJsonLines(book));
  saveFile(logFileName(new Date()), "application/x-ndjson", bytes);
}

function EventLogComponent({
  book,
  open,
  onToggle,
  onClear,
}: {
  book: LogBook;
  open: boolean;
  onToggle(): void;
  onClear(): void;
}) {
  const current = currentEntries(book);
  const earlier = earlierEntries(book);
  return (
    <section className={`event-log${open ? " is-open" : ""}`} aria-label="Event log">
      <header className="event-log__head">
        <button
          type="button"
          className="event-log__toggle"
          aria-expanded={open}
          aria-controls="event-log-list"
          onClick={onToggle}
        >
          <span aria-hidden="true">{open ? "▾" : "▸"}</span> Log
        </button>
        <Counts book={book} />
        {book.entries.length > 0 ? (
          <button
            type="button"
            className="event-log__clear"
            title="Save the whole log (every load) as a JSON Lines file"
            onClick={() => downloadLog(book)}
          >
            Download
          </button>
        ) : null}
        {open && book.entries.length > 0 ? (
          <button type="button" className="event-log__clear" onClick={onClear}>
            Clear
          </button>
        ) : null}
      </header>
      {open ? (
        <div className="event-log__body">
          <ol id="event-log-list" className="event-log__list" aria-live="polite">
            {current.length === 0 ? <li className="event-log__empty">Nothing yet.</li> : null}
            {[...current].reverse().map((e) => (
              <Entry key={e.id} e={e} />
            ))}
          </ol>
          {earlier.length > 0 ? (
            <details className="event-log__earlier">
              <summary>Earlier loads ({earlier.length})</summary>
              <ol className="event-log__list">
                {[...earlier].reverse().map((e) => (
                  <Entry key={e.id} e={e} />
                ))}
              </ol>
            </details>
          ) : null}
        </div>
      ) : null}
    </section>
  );
}

export const EventLog = memo(EventLogComponent);
