/**
 * The editor's right column: the inspector above the YAML. Where the window is not tall enough
 * for both (issue 17, defect 8: at 1280×720 the inspector was squeezed to its headings), they
 * are two tabs instead, each with the whole height; selecting a block shows its inspector.
 */
import { useEffect, useState, type ReactNode } from "react";
import "./side-pane.css";

/** Below this window height the inspector and the YAML take turns. */
export const TABBED_BELOW_PX = 820;

type Tab = "inspector" | "yaml";

function useShortWindow(): boolean {
  const q = `(max-height: ${TABBED_BELOW_PX - 0.02}px)`;
  const [short, setShort] = useState(() => window.matchMedia?.(q).matches ?? false);
  useEffect(() => {
    const m = window.matchMedia?.(q);
    if (!m) return undefined;
    const on = (): void => setShort(m.matches);
    m.addEventListener("change", on);
    return () => m.removeEventListener("change", on);
  }, [q]);
  return short;
}

function TabBar({ tab, onTab }: { tab: Tab; onTab(t: Tab): void }) {
  const item = (t: Tab, label: string) => (
    <button
      type="button"
      role="tab"
      id={`side-pane-tab-${t}`}
      aria-selected={tab === t}
      aria-controls={`side-pane-${t}`}
      className="side-pane__tab"
      onClick={() => onTab(t)}
    >
      {label}
    </button>
  );
  return (
    <div className="side-pane__tabs" role="tablist" aria-label="Inspector or YAML">
      {item("inspector", "Inspector")}
      {item("yaml", "YAML")}
    </div>
  );
}

export function SidePane({
  selected,
  inspector,
  text,
}: {
  /** The selected block (a new selection shows the inspector). */
  selected: string | null;
  inspector: ReactNode;
  text: ReactNode;
}) {
  const short = useShortWindow();
  const [tab, setTab] = useState<Tab>(selected !== null ? "inspector" : "yaml");
  useEffect(() => {
    if (selected !== null) setTab("inspector");
  }, [selected]);
  if (!short) {
    return (
      <div className="editor__side">
        {inspector}
        {text}
      </div>
    );
  }
  return (
    <div className="editor__side is-tabbed">
      <TabBar tab={tab} onTab={setTab} />
      <div
        id="side-pane-inspector"
        role="tabpanel"
        aria-labelledby="side-pane-tab-inspector"
        className="side-pane__panel"
        hidden={tab !== "inspector"}
      >
        {inspector}
      </div>
      <div
        id="side-pane-yaml"
        role="tabpanel"
        aria-labelledby="side-pane-tab-yaml"
        className="side-pane__panel"
        hidden={tab !== "yaml"}
      >
        {text}
      </div>
    </div>
  );
}
