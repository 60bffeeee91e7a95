/**
 * The ChannelPicker's open strip: the range box, the quick picks (all, none, previous and next
 * page), an error or a warning, and, up to MANY_CHANNELS channels, one toggle per channel.
 */
import { DEFAULT_MAX_CHANNELS, channelColor, channelLabel, range } from "./channels";
import type { OutputInfo } from "./view-props";

/** More than this many plotted channels gets a warning (legibility and drawing time). */
export const MANY_CHANNELS = 64;

/** The range box's state (ChannelPicker's useRangeText). */
export interface RangeText {
  text: string;
  setText(text: string): void;
  error: string;
  apply(text: string): void;
}

interface Selection {
  count: number;
  selected: readonly number[];
  onChange: (channels: number[]) => void;
}

export function ChannelPickerBody({
  count,
  selected,
  output,
  onChange,
  rangeText,
}: Selection & { output: OutputInfo; rangeText: RangeText }) {
  const { error } = rangeText;
  return (
    <span className="mp-picker-body">
      <RangeField {...rangeText} />
      <QuickPicks count={count} selected={selected} onChange={onChange} />
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
        <ChannelToggles count={count} selected={selected} output={output} onChange={onChange} />
      )}
    </span>
  );
}

/** "Show [0-7, 12]": applied on Enter and when the box loses the focus. */
function RangeField({ text, setText, error, apply }: RangeText) {
  return (
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
  );
}

/** all, none, and with more channels than a page, the previous and next page. */
function QuickPicks({ count, selected, onChange }: Selection) {
  return (
    <>
      <button type="button" className="mp-btn mp-small" onClick={() => onChange(range(0, count))}>
        all
      </button>
      <button type="button" className="mp-btn mp-small" onClick={() => onChange([])}>
        none
      </button>
      {count > DEFAULT_MAX_CHANNELS && (
        <PageButtons count={count} selected={selected} onChange={onChange} />
      )}
    </>
  );
}

/** ‹ prev 16, next 16 ›: the page before or after the one the selection starts in. */
function PageButtons({ count, selected, onChange }: Selection) {
  const page = DEFAULT_MAX_CHANNELS;
  const first = selected[0] ?? 0;
  return (
    <>
      <button
        type="button"
        className="mp-btn mp-small"
        disabled={first === 0}
        onClick={() => onChange(pageFrom(Math.max(0, first - page), count))}
      >
        ‹ prev {page}
      </button>
      <button
        type="button"
        className="mp-btn mp-small"
        disabled={first + page >= count}
        onClick={() => onChange(pageFrom(Math.min(count - 1, first + page), count))}
      >
        next {page} ›
      </button>
    </>
  );
}

/** A page of channels from `start`, cut at `count`. */
function pageFrom(start: number, count: number): number[] {
  return range(start, Math.min(count, start + DEFAULT_MAX_CHANNELS));
}

/** One checkbox per channel, with its trace's colour and its label. */
function ChannelToggles({ count, selected, output, onChange }: Selection & { output: OutputInfo }) {
  const set = new Set(selected);
  return (
    <span className="mp-toggles" role="group" aria-label="Channel toggles">
      {range(0, count).map((c) => (
        <label key={c} className={`mp-toggle${set.has(c) ? " mp-on" : ""}`}>
          <input
            type="checkbox"
            checked={set.has(c)}
            onChange={() => onChange(toggled(selected, c, set.has(c)))}
          />
          <span className="mp-swatch" style={{ background: channelColor(c) }} aria-hidden="true" />
          {channelLabel(output, c)}
        </label>
      ))}
    </span>
  );
}

/** The selection with channel `c` taken out (when `on`) or put in, in order. */
function toggled(selected: readonly number[], c: number, on: boolean): number[] {
  return on ? selected.filter((x) => x !== c) : [...selected, c].sort((a, b) => a - b);
}
