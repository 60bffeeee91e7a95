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
import { usePanelDrag } from "./panel-drag";
import { PanelFrameHead } from "./panel-frame-head";
import { PopOut } from "./pop-out";
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

interface FrameProps {
  panel: OpenPanel;
  block: BlockInfo;
  pageVisible: boolean;
  onEditStatic: EditStatic | undefined;
  onClose(): void;
  onUpdate(p: Partial<OpenPanel>): void;
  onRaise(): void;
}

/** One open panel: its title bar and the block's panel (hidden while collapsed). */
function PanelFrame({
  panel,
  block,
  pageVisible,
  onEditStatic,
  onClose,
  onUpdate,
  onRaise,
}: FrameProps) {
  const ref = useRef<HTMLElement>(null);
  const onScreen = useOnScreen(ref);
  // Popped out into its own window, it is shown whatever this page's layout does.
  const [popped, setPopped] = useState(false);
  const visible = popped || (!panel.collapsed && onScreen && pageVisible);
  const drag = usePanelDrag(ref, panel, onUpdate);
  usePanelSize(ref, panel.floating, panel, onUpdate);
  useAvoidNode(ref, block.name, panel.floating, onUpdate);

  const titleId = `panel-title-${block.name}`;
  return (
    <section
      ref={ref}
      className={`panel-frame${panel.floating ? " is-floating" : " is-docked"}${panel.collapsed ? " is-collapsed" : ""}`}
      style={frameStyle(panel)}
      aria-labelledby={titleId}
      data-panel={block.name}
      data-visible={String(visible)}
      onPointerDownCapture={onRaise}
    >
      <PanelFrameHead
        panel={panel}
        block={block}
        titleId={titleId}
        popped={popped}
        setPopped={setPopped}
        drag={drag}
        onClose={onClose}
        onUpdate={onUpdate}
      />
      <PanelFrameBody
        panel={panel}
        block={block}
        visible={visible}
        popped={popped}
        setPopped={setPopped}
        onEditStatic={onEditStatic}
        onClose={onClose}
        onUpdate={onUpdate}
      />
    </section>
  );
}

/** The block's panel (in its own window while popped out), hidden while collapsed. */
function PanelFrameBody({
  panel,
  block,
  visible,
  popped,
  setPopped,
  onEditStatic,
  onClose,
  onUpdate,
}: Omit<FrameProps, "pageVisible" | "onRaise"> & {
  visible: boolean;
  popped: boolean;
  setPopped(popped: boolean): void;
}) {
  const ui = useUi();
  return (
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
  );
}

/** A floating window's place, stacking and size (a collapsed one keeps only its width). */
function frameStyle(panel: OpenPanel): React.CSSProperties | undefined {
  return panel.floating
    ? {
        left: panel.x,
        top: panel.y,
        zIndex: panel.z,
        ...(panel.width !== undefined ? { width: panel.width } : {}),
        ...(panel.height !== undefined && !panel.collapsed ? { height: panel.height } : {}),
      }
    : undefined;
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
