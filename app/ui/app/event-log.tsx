/** The log of runtime events (errors and warnings per block) and of the replies to actions. */
import { memo } from "react";

export interface LogEntry {
  id: number;
  /** UNIX seconds. */
  t: number;
  level: "error" | "warning" | "info";
  block: string;
  message: string;
}

const time = (t: number): string => {
  const d = new Date(t * 1000);
  const p = (n: number, w = 2) => String(n).padStart(w, "0");
  return `${p(d.getHours())}:${p(d.getMinutes())}:${p(d.getSeconds())}`;
};

const LEVEL_MARK: Record<LogEntry["level"], string> = { error: "✖", warning: "▲", info: "●" };

function EventLogComponent({
  entries,
  open,
  onToggle,
  onClear,
}: {
  entries: readonly LogEntry[];
  open: boolean;
  onToggle(): void;
  onClear(): void;
}) {
  const errors = entries.filter((e) => e.level === "error").length;
  const warnings = entries.filter((e) => e.level === "warning").length;
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
        <span className="event-log__counts" data-errors={errors} data-warnings={warnings}>
          {errors > 0 ? (
            <span className="count-error">
              {errors} error{errors === 1 ? "" : "s"}
            </span>
          ) : null}
          {warnings > 0 ? (
            <span className="count-warning">
              {warnings} warning{warnings === 1 ? "" : "s"}
            </span>
          ) : null}
          {errors === 0 && warnings === 0 ? <span>no errors</span> : null}
        </span>
        {open && entries.length > 0 ? (
          <button type="button" className="event-log__clear" onClick={onClear}>
            Clear
          </button>
        ) : null}
      </header>
      {open ? (
        <ol id="event-log-list" className="event-log__list" aria-live="polite">
          {entries.length === 0 ? <li className="event-log__empty">Nothing yet.</li> : null}
          {[...entries].reverse().map((e) => (
            <li key={e.id} className={`event-log__entry level-${e.level}`} data-level={e.level}>
              <span className="event-log__mark" aria-hidden="true">
                {LEVEL_MARK[e.level]}
              </span>
              <time>{time(e.t)}</time>
              <span className="event-log__level">{e.level}</span>
              {e.block ? <strong className="event-log__block">{e.block}</strong> : null}
              <span className="event-log__message">{e.message}</span>
            </li>
          ))}
        </ol>
      ) : null}
    </section>
  );
}

export const EventLog = memo(EventLogComponent);
