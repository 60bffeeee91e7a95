/**
 * How a timing status looks (paper III-B): colour, a word and an icon, so that colour is never
 * the only signal. The colours live in styles.css (`--status-*`).
 */
import type { Status } from "../../engine/runtime/status";

export type { Status };

export const STATUS_LABEL: Record<Status, string> = {
  ontime: "on time",
  lagging: "lagging",
  stumbling: "stumbling",
  idle: "idle",
};

export const STATUS_HELP: Record<Status, string> = {
  ontime: "on time: at least 95 % of its desired rate",
  lagging: "lagging: below 95 % of its desired rate",
  stumbling: "stumbling: one call took longer than a period",
  idle: "idle: no output for 10 periods (at least 50 ms)",
};

/** Short label of a block's status; "lagging, stumbling" when both hold. */
export function statusText(status: Status, stumbling: boolean): string {
  return status === "lagging" && stumbling ? "lagging, stumbling" : STATUS_LABEL[status];
}

/** A small icon per status (SVG: no font dependency), hidden from screen readers. */
export function StatusIcon({ status }: { status: Status }) {
  const common = {
    width: 14,
    height: 14,
    viewBox: "0 0 16 16",
    "aria-hidden": true,
    focusable: false,
    className: "status-icon",
  } as const;
  switch (status) {
    case "ontime":
      return (
        <svg {...common}>
          <circle cx="8" cy="8" r="7.5" fill="currentColor" opacity="0.18" />
          <path
            d="M4.2 8.4l2.5 2.5 5-5.4"
            fill="none"
            stroke="currentColor"
            strokeWidth="2"
            strokeLinecap="round"
            strokeLinejoin="round"
          />
        </svg>
      );
    case "lagging":
      // a slow-down arrow
      return (
        <svg {...common}>
          <circle cx="8" cy="8" r="7.5" fill="currentColor" opacity="0.18" />
          <path
            d="M8 3.5v8M4.5 8.5L8 12l3.5-3.5"
            fill="none"
            stroke="currentColor"
            strokeWidth="2"
            strokeLinecap="round"
            strokeLinejoin="round"
          />
        </svg>
      );
    case "stumbling":
      // a spike (one slow call)
      return (
        <svg {...common}>
          <circle cx="8" cy="8" r="7.5" fill="currentColor" opacity="0.18" />
          <path
            d="M2.5 9.5h3l1.5-5 2 8 1.5-3h3"
            fill="none"
            stroke="currentColor"
            strokeWidth="1.8"
            strokeLinecap="round"
            strokeLinejoin="round"
          />
        </svg>
      );
    case "idle":
      // pause
      return (
        <svg {...common}>
          <circle cx="8" cy="8" r="7.5" fill="currentColor" opacity="0.18" />
          <path d="M6 5v6M10 5v6" stroke="currentColor" strokeWidth="2" strokeLinecap="round" />
        </svg>
      );
  }
}

/** "200 Hz", "25.0 Hz", "0.50 Hz": whole numbers from 100 Hz up, so the label does not flicker. */
export function formatRate(hz: number): string {
  if (!(hz > 0) || !Number.isFinite(hz)) return "–";
  if (hz >= 100) return `${Math.round(hz)}`;
  if (hz >= 1) return hz.toFixed(1);
  return hz.toFixed(2);
}
