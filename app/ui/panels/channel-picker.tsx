/**
 * A compact channel selector: a summary button that opens a strip with a range box ("0-7, 12"),
 * quick picks (all, none, pages of 16) and, up to 64 channels, one toggle per channel.
 */
import { useEffect, useState, type ReactNode } from "react";
import {
  DEFAULT_MAX_CHANNELS,
  channelColor,
  channelLabel,
  formatChannelSelection,
  parseChannelSelection,
  range,
} from "./channels";
import type { OutputInfo } from "./view-props";

/** More than this many plotted channels gets a warning (legibility and drawing time). */
export const MANY_CHANNELS = 64;

export function ChannelPicker({
  count,
  selected,
  output,
  onChange,
}: {
  count: number;
  selected: readonly number[];
  output: OutputInfo;
  onChange: (channels: number[]) => void;
}): ReactNode {
  const [open, setOpen] = useState(false);
  const [text, setText] = useState(formatChannelSelection(selected));
  const [error, setError] = useState("");
  useEffect(() => {
    setText(formatChannelSelection(selected));
    setError("");
  }, [selected]);
  if (count <= 1) return null;
  const apply = (t: string): void => {
    const r = parseChannelSelection(t, count);
    if (!r.ok) {
      setError(r.error);
      return;
    }
    setError("");
    onChange(r.channels);
  };
  const page = DEFAULT_MAX_CHANNELS;
  const first = selected[0] ?? 0;
  const set = new Set(selected);
  return (
    <span className="mp-picker">
      <button
        type="button"
        className={`mp-btn${open ? " mp-on" : ""}`}
        aria-expanded={open}
        onClick={() => setOpen(!open)}
        title="Choose the plotted channels"
      >
        Channels: {selected.length === count ? "all" : formatChannelSelection(selected) || "none"}{" "}
        <span className="mp-muted">
          ({selected.length} of {count})
        </span>{" "}
        ▾
      </button>
      {open && (
        <span className="mp-picker-body">
          <label className="mp-field">
            Show
            <input
              className="mp-range-input"
              value={text}
              aria-label="Channels to show, e.g. 0-7, 12"
              aria-invalid={!!error}
              placeholder="e.g. 0-7, 12"
              onChange={(e) => setText(e.target.value)}
              onKeyDown={(e) => e.key === "Enter" && apply(text)}
              onBlur={() => apply(text)}
            />
          </label>
          <button
            type="button"
            className="mp-btn mp-small"
            onClick={() => onChange(range(0, count))}
          >
            all
          </button>
          <button type="button" className="mp-btn mp-small" onClick={() => onChange([])}>
            none
          </button>
          {count > page && (
            <>
              <button
                type="button"
                className="mp-btn mp-small"
                disabled={first === 0}
                onClick={() => {
                  const s = Math.max(0, first - page);
                  onChange(range(s, Math.min(count, s + page)));
                }}
              >
                ‹ prev {page}
              </button>
              <button
                type="button"
                className="mp-btn mp-small"
                disabled={first + page >= count}
                onClick={() => {
                  const s = Math.min(count - 1, first + page);
                  onChange(range(s, Math.min(count, s + page)));
                }}
              >
                next {page} ›
              </button>
            </>
          )}
          {error && (
            <span className="mp-error" role="alert">
              {error}
            </span>
          )}
          {selected.length > MANY_CHANNELS && (
            <span className="mp-warn">
              {selected.length} channels: hard to read, and slower to draw
            </span>
          )}
          {count <= MANY_CHANNELS && (
            <span className="mp-toggles" role="group" aria-label="Channel toggles">
              {range(0, count).map((c) => (
                <label key={c} className={`mp-toggle${set.has(c) ? " mp-on" : ""}`}>
                  <input
                    type="checkbox"
                    checked={set.has(c)}
                    onChange={() =>
                      onChange(
                        set.has(c)
                          ? selected.filter((x) => x !== c)
                          : [...selected, c].sort((a, b) => a - b),
                      )
                    }
                  />
                  <span
                    className="mp-swatch"
                    style={{ background: channelColor(c) }}
                    aria-hidden="true"
                  />
                  {channelLabel(output, c)}
                </label>
              ))}
            </span>
          )}
        </span>
      )}
    </span>
  );
}
