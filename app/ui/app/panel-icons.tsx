/** The icons of a panel frame's title bar (PanelFrame): 16 px, stroked in the text colour. */
const icon = { width: 16, height: 16, viewBox: "0 0 16 16", "aria-hidden": true } as const;
const stroke = {
  fill: "none",
  stroke: "currentColor",
  strokeWidth: 1.6,
  strokeLinecap: "round",
  strokeLinejoin: "round",
} as const;

/** A window popping out of a frame. */
export function FloatIcon() {
  return (
    <svg {...icon}>
      <rect x="1.5" y="4.5" width="10" height="10" rx="1.5" {...stroke} />
      <path d="M8 1.5h6.5V8M14.5 1.5L8 8" {...stroke} />
    </svg>
  );
}

/** A window going into the side area. */
export function DockIcon() {
  return (
    <svg {...icon}>
      <rect x="1.5" y="1.5" width="13" height="13" rx="1.5" {...stroke} />
      <path d="M10 1.5v13" {...stroke} />
      <path d="M4 8h4M6 6l2 2-2 2" {...stroke} />
    </svg>
  );
}

export function CloseIcon() {
  return (
    <svg {...icon}>
      <path d="M3.5 3.5l9 9M12.5 3.5l-9 9" {...stroke} strokeWidth={1.9} />
    </svg>
  );
}

export function ChevronIcon({ open }: { open: boolean }) {
  return (
    <svg {...icon}>
      <path
        d={open ? "M3.5 6l4.5 4.5L12.5 6" : "M6 3.5l4.5 4.5L6 12.5"}
        {...stroke}
        strokeWidth={1.9}
      />
    </svg>
  );
}
