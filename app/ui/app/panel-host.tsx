/**
 * Where control panels live: docked in the side area (stacked, each collapsible) or floating
 * over the BlockTable (draggable windows, raised on click). Several are open at once. A panel is
 * `visible` only while it is expanded, on screen (scrolled into the dock's view) and the page is
 * shown; a hidden or closed panel unwatches its data (paper III-C: updates only while visible).
 */
import { useEffect, useRef, useState, type ReactNode } from "react";
import type { BlockInfo } from "../../engine/protocol";
import type { SetResult } from "../forms/params-form";
import { BlockPanel } from "../panels/block-panel";
import { useAvoidNode } from "./use-avoid-node";
import type { PanelView } from "./panel-layouts";
import { DockResizer, useDockWidth } from "./dock-resizer";
import { PopOut, PopOutButton } from "./pop-out";
import { StatusDot } from "./status-dot";
import { usePanelSize } from "./use-panel-size";
import { useUi } from "./ui-context";

/** Changes a param that is not live: the host edits the file and reloads it (not running). */
export type EditStatic = (block: string, param: string, value: unknown) => Promise<SetResult>;

export interface OpenPanel {
  name: string;
  floating: boolean;
  collapsed: boolean;
  x: number;
  y: number;
  z: number;
  /** Size of a floating panel the user resized, px. */
  width?: number;
  height?: number;
  /** Its view (tab, output, view settings) as last reported, for saved panel layouts. */
  view?: PanelView;
}

/** Whether the page is shown (not a background tab, not minimised). */
function usePageVisible(): boolean {
  const [v, setV] = useState(() => document.visibilityState !== "hidden");
  useEffect(() => {
    const on = (): void => setV(document.visibilityState !== "hidden");
    document.addEventListener("visibilitychange", on);
    return () => document.removeEventListener("visibilitychange", on);
  }, []);
  return v;
}

/** Whether an element is (at least partly) inside its scroll container's view. */
function useOnScreen(ref: React.RefObject<HTMLElement | null>): boolean {
  const [on, setOn] = useState(true);
  useEffect(() => {
    const el = ref.current;
    if (!el || typeof IntersectionObserver !== "function") return undefined;
    const io = new IntersectionObserver((es) => setOn(es.some((e) => e.isIntersecting)), {
      threshold: 0,
    });
    io.observe(el);
    return () => io.disconnect();
  }, [ref]);
  return on;
}

const icon = { width: 16, height: 16, viewBox: "0 0 16 16", "aria-hidden": true } as const;
const stroke = {
  fill: "none",
  stroke: "currentColor",
  strokeWidth: 1.6,
  strokeLinecap: "round",
  strokeLinejoin: "round",
} as const;

/** A window popping out of a frame. */
function FloatIcon() {
  return (
    <svg {...icon}>
      <rect x="1.5" y="4.5" width="10" height="10" rx="1.5" {...stroke} />
      <path d="M8 1.5h6.5V8M14.5 1.5L8 8" {...stroke} />
    </svg>
  );
}

/** A window going into the side area. */
function DockIcon() {
  return (
    <svg {...icon}>
      <rect x="1.5" y="1.5" width="13" height="13" rx="1.5" {...stroke} />
      <path d="M10 1.5v13" {...stroke} />
      <path d="M4 8h4M6 6l2 2-2 2" {...stroke} />
    </svg>
  );
}

function CloseIcon() {
  return (
    <svg {...icon}>
      <path d="M3.5 3.5l9 9M12.5 3.5l-9 9" {...stroke} strokeWidth={1.9} />
    </svg>
  );
}

function ChevronIcon({ open }: { open: boolean }) {
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

interface FrameProps {
  panel: OpenPanel;
  block: BlockInfo;
  pageVisible: boolean;
  onEditStatic: EditStatic | undefined;
  onClose(): void;
  onUpdate(p: Partial<OpenPanel>): void;
  onRaise(): void;
}

function PanelFrame({
  panel,
  block,
  pageVisible,
  onEditStatic,
  onClose,
  onUpdate,
  onRaise,
}: FrameProps) {
  const ui = useUi();
  const ref = useRef<HTMLElement>(null);
  const onScreen = useOnScreen(ref);
  // Popped out into its own window, it is shown whatever this page's layout does.
  const [popped, setPopped] = useState(false);
  const visible = popped || (!panel.collapsed && onScreen && pageVisible);
  const drag = useRef<{ dx: number; dy: number } | null>(null);
  usePanelSize(ref, panel.floating, panel, onUpdate);
  useAvoidNode(ref, block.name, panel.floating, onUpdate);

  const onPointerDown = (e: React.PointerEvent<HTMLElement>): void => {
    if (!panel.floating || e.button !== 0) return;
    if ((e.target as HTMLElement).closest("button")) return;
    const el = ref.current!;
    drag.current = { dx: e.clientX - el.offsetLeft, dy: e.clientY - el.offsetTop };
    e.currentTarget.setPointerCapture(e.pointerId);
  };
  const onPointerMove = (e: React.PointerEvent<HTMLElement>): void => {
    const d = drag.current;
    const el = ref.current;
    if (!d || !el) return;
    const parent = el.offsetParent as HTMLElement | null;
    const maxX = (parent?.clientWidth ?? window.innerWidth) - 80;
    const maxY = (parent?.clientHeight ?? window.innerHeight) - 32;
    // Moved directly (no React render per pointer event); committed on release.
    el.style.left = `${Math.max(-200, Math.min(maxX, e.clientX - d.dx))}px`;
    el.style.top = `${Math.max(0, Math.min(maxY, e.clientY - d.dy))}px`;
  };
  const onPointerUp = (): void => {
    const el = ref.current;
    if (drag.current && el) onUpdate({ x: el.offsetLeft, y: el.offsetTop });
    drag.current = null;
  };
  const onHeadKey = (e: React.KeyboardEvent<HTMLElement>): void => {
    // Floating windows move with the arrow keys while their title bar has the focus.
    if (!panel.floating || e.target !== e.currentTarget) return;
    const step = e.shiftKey ? 40 : 10;
    const d = {
      ArrowLeft: [-step, 0],
      ArrowRight: [step, 0],
      ArrowUp: [0, -step],
      ArrowDown: [0, step],
    }[e.key];
    if (!d) return;
    e.preventDefault();
    onUpdate({ x: panel.x + d[0]!, y: Math.max(0, panel.y + d[1]!) });
  };

  const titleId = `panel-title-${block.name}`;
  return (
    <section
      ref={ref}
      className={`panel-frame${panel.floating ? " is-floating" : " is-docked"}${panel.collapsed ? " is-collapsed" : ""}`}
      style={
        panel.floating
          ? {
              left: panel.x,
              top: panel.y,
              zIndex: panel.z,
              ...(panel.width !== undefined ? { width: panel.width } : {}),
              ...(panel.height !== undefined && !panel.collapsed ? { height: panel.height } : {}),
            }
          : undefined
      }
      aria-labelledby={titleId}
      data-panel={block.name}
      data-visible={String(visible)}
      onPointerDownCapture={onRaise}
    >
      <header
        className="panel-frame__head"
        onPointerDown={onPointerDown}
        onPointerMove={onPointerMove}
        onPointerUp={onPointerUp}
        onPointerCancel={onPointerUp}
        onKeyDown={onHeadKey}
        tabIndex={panel.floating ? 0 : undefined}
        aria-label={panel.floating ? `${block.name} window: arrow keys move it` : undefined}
      >
        <button
          type="button"
          className="panel-frame__collapse"
          aria-expanded={!panel.collapsed}
          aria-controls={`panel-body-${block.name}`}
          aria-label={`${panel.collapsed ? "Expand" : "Collapse"} the panel of ${block.name}`}
          onClick={() => onUpdate({ collapsed: !panel.collapsed })}
        >
          <ChevronIcon open={!panel.collapsed} />
        </button>
        <StatusDot block={block.name} />
        <h2 id={titleId} className="panel-frame__title">
          {block.name} <span className="panel-frame__type">{block.type}</span>
        </h2>
        <PopOutButton name={block.name} popped={popped} onToggle={() => setPopped(!popped)} />
        <button
          type="button"
          className="panel-frame__float"
          aria-label={
            panel.floating ? `Dock the panel of ${block.name}` : `Float the panel of ${block.name}`
          }
          title={panel.floating ? "Dock in the side area" : "Float as a window"}
          onClick={() => onUpdate({ floating: !panel.floating })}
        >
          {panel.floating ? <DockIcon /> : <FloatIcon />}
        </button>
        <button
          type="button"
          className="panel-frame__close"
          aria-label={`Close the panel of ${block.name}`}
          title="Close"
          onClick={onClose}
        >
          <CloseIcon />
        </button>
      </header>
      <div id={`panel-body-${block.name}`} className="panel-frame__body" hidden={panel.collapsed}>
        <PopOut
          name={block.name}
          title={`${block.name} · MOSAIC`}
          popped={popped}
          onClosed={() => setPopped(false)}
        >
          <BlockPanel
            block={block}
            visible={visible}
            onClose={onClose}
            {...(panel.view ? { view: panel.view } : {})}
            onView={(view) => onUpdate({ view })}
            {...(block.type === "Stimulus"
              ? { onOpenStimulus: () => ui.openStimulus(block.name) }
              : {})}
            {...(onEditStatic
              ? {
                  onEditStatic: (param: string, value: unknown) =>
                    onEditStatic(block.name, param, value),
                }
              : {})}
          />
        </PopOut>
      </div>
    </section>
  );
}

export function PanelHost({
  panels,
  blocks,
  onEditStatic,
  onClose,
  onUpdate,
  onRaise,
  children,
}: {
  panels: readonly OpenPanel[];
  blocks: ReadonlyMap<string, BlockInfo>;
  onEditStatic?: EditStatic;
  onClose(name: string): void;
  onUpdate(name: string, p: Partial<OpenPanel>): void;
  onRaise(name: string): void;
  /** The BlockTable, under the floating windows. */
  children: ReactNode;
}) {
  const pageVisible = usePageVisible();
  const [dockWidth, setDockWidth] = useDockWidth();
  const frame = (p: OpenPanel) => {
    const block = blocks.get(p.name);
    if (!block) return null;
    return (
      <PanelFrame
        key={p.name}
        panel={p}
        block={block}
        pageVisible={pageVisible}
        onEditStatic={onEditStatic}
        onClose={() => onClose(p.name)}
        onUpdate={(u) => onUpdate(p.name, u)}
        onRaise={() => onRaise(p.name)}
      />
    );
  };
  const docked = panels.filter((p) => !p.floating);
  const floating = panels.filter((p) => p.floating);
  return (
    <div className={`workspace${docked.length > 0 ? " has-dock" : ""}`}>
      <div className="workspace__graph">
        {children}
        <div className="floating-layer">{floating.map(frame)}</div>
      </div>
      {docked.length > 0 ? <DockResizer width={dockWidth} onWidth={setDockWidth} /> : null}
      {docked.length > 0 ? (
        <aside
          className="dock"
          aria-label="Control panels"
          style={dockWidth !== undefined ? { width: dockWidth } : undefined}
        >
          {docked.map(frame)}
        </aside>
      ) : null}
    </div>
  );
}
