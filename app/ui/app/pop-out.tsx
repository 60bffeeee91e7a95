/**
 * A control panel in its own browser window (a second monitor, a projector): the panel's
 * content is rendered into a window the page opens (same origin, the page's stylesheets copied
 * in) through a React portal, so it stays one React tree on one engine connection. Closing that
 * window, or the button left in the panel's place, brings it back. Drawing follows the page's
 * animation frames: the page must stay shown (not minimised) for the window's plots to move.
 */
import { useEffect, useState, type ReactNode } from "react";
import { createPortal } from "react-dom";

const icon = { width: 16, height: 16, viewBox: "0 0 16 16", "aria-hidden": true } as const;

/** Two windows, the front one leaving. */
function PopOutIcon(): ReactNode {
  return (
    <svg {...icon}>
      <rect
        x="1.5"
        y="5.5"
        width="9"
        height="9"
        rx="1"
        fill="none"
        stroke="currentColor"
        strokeWidth={1.5}
      />
      <rect
        x="5.5"
        y="1.5"
        width="9"
        height="9"
        rx="1"
        fill="none"
        stroke="currentColor"
        strokeWidth={1.5}
      />
    </svg>
  );
}

export function PopOutButton({
  name,
  popped,
  onToggle,
}: {
  name: string;
  popped: boolean;
  onToggle(): void;
}): ReactNode {
  return (
    <button
      type="button"
      className="panel-frame__popout"
      aria-pressed={popped}
      aria-label={
        popped
          ? `Bring the panel of ${name} back`
          : `Pop the panel of ${name} out into its own window`
      }
      title={popped ? "Bring back into this page" : "Pop out into its own window"}
      onClick={onToggle}
    >
      <PopOutIcon />
    </button>
  );
}

/** Opens the window and copies the page's styles into it; null when the browser refused. */
function openWindow(name: string, title: string): Window | null {
  const w = window.open("", `mosaic-panel-${name}`, "popup,width=760,height=620");
  if (!w) return null;
  const doc = w.document;
  doc.title = title;
  doc.head.replaceChildren(
    ...Array.from(document.querySelectorAll('style, link[rel="stylesheet"]'), (n) =>
      doc.importNode(n, true),
    ),
  );
  doc.body.replaceChildren();
  doc.body.className = "popout-body";
  doc.documentElement.lang = document.documentElement.lang;
  return w;
}

/**
 * `children` inline, or (popped) in a window of their own with a note in their place. `onClosed`
 * runs when that window is closed by its user or cannot be opened.
 */
export function PopOut({
  name,
  title,
  popped,
  onClosed,
  children,
}: {
  name: string;
  title: string;
  popped: boolean;
  onClosed(): void;
  children: ReactNode;
}): ReactNode {
  const [host, setHost] = useState<HTMLElement | null>(null);
  const [refused, setRefused] = useState(false);
  useEffect(() => {
    if (!popped) return undefined;
    const w = openWindow(name, title);
    if (!w) {
      setRefused(true);
      onClosed();
      return undefined;
    }
    setRefused(false);
    const root = w.document.createElement("div");
    root.className = "popout-root";
    root.style.padding = "8px";
    root.dataset.popout = name;
    w.document.body.append(root);
    setHost(root);
    // Closed by its user: no event says so reliably (pagehide also fires when the blank first
    // document is replaced), so the page looks twice a second.
    const timer = setInterval(() => {
      if (w.closed) onClosed();
    }, 500);
    return () => {
      clearInterval(timer);
      setHost(null);
      w.close();
    };
    // The window is opened per pop-out; title and onClosed changes do not reopen it.
  }, [popped, name]);
  if (!popped || !host)
    return (
      <>
        {refused && (
          <p className="mp-error" role="alert">
            The browser blocked the new window: allow pop-ups for this page to pop a panel out.
          </p>
        )}
        {children}
      </>
    );
  return (
    <>
      <p className="mp-muted popout-note">Shown in its own window.</p>
      {createPortal(children, host)}
    </>
  );
}
