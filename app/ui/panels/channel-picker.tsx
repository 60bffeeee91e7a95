/**
 * A compact channel selector: a summary button that opens a strip with a range box ("0-7, 12"),
 * quick picks (all, none, pages of 16) and, up to 64 channels, one toggle per channel.
 */
import { useEffect, useState, type ReactNode } from "react";
import { ChannelPickerBody, type RangeText } from "./channel-picker-body";
import { formatChannelSelection, parseChannelSelection } from "./channels";
import type { OutputInfo } from "./view-props";

export { MANY_CHANNELS } from "./channel-picker-body";

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
  const rangeText = useRangeText(selected, count, onChange);
  if (count <= 1) return null;
  return (
    <span className="mp-picker">
      <SummaryButton
        open={open}
        onToggle={() => setOpen(!open)}
        selected={selected}
        count={count}
      />
      {open && (
        <ChannelPickerBody
          count={count}
          selected={selected}
          output={output}
          onChange={onChange}
          rangeText={rangeText}
        />
      )}
    </span>
  );
}

/** "Channels: 0-7, 12 (9 of 32) ▾": opens and closes the strip. */
function SummaryButton({
  open,
  onToggle,
  selected,
  count,
}: {
  open: boolean;
  onToggle(): void;
  selected: readonly number[];
  count: number;
}) {
  return (
    <button
      type="button"
      className={`mp-btn${open ? " mp-on" : ""}`}
      aria-expanded={open}
      onClick={onToggle}
      title="Choose the plotted channels"
    >
      Channels: {selected.length === count ? "all" : formatChannelSelection(selected) || "none"}{" "}
      <span className="mp-muted">
        ({selected.length} of {count})
      </span>{" "}
      ▾
    </button>
  );
}

/**
 * The range box's text and error: reset when the selection changes; `apply` parses the text and
 * hands the channels on, or shows why it cannot.
 */
function useRangeText(
  selected: readonly number[],
  count: number,
  onChange: (channels: number[]) => void,
): RangeText {
  const [text, setText] = useState(formatChannelSelection(selected));
  const [error, setError] = useState("");
  useEffect(() => {
    setText(formatChannelSelection(selected));
    setError("");
  }, [selected]);
  const apply = (t: string): void => {
    const r = parseChannelSelection(t, count);
    if (!r.ok) {
      setError(r.error);
      return;
    }
    setError("");
    onChange(r.channels);
  };
  return { text, setText, error, apply };
}
