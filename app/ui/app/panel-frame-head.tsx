/**
 * A panel frame's title bar (PanelFrame): collapse, status, title, pop out, float or dock, close.
 * A floating window's bar takes the focus and moves it (see usePanelDrag).
 */
import type { BlockInfo } from "../../engine/protocol";
import type { DragHandlers } from "./panel-drag";
import type { OpenPanel } from "./panel-host";
import { ChevronIcon, CloseIcon, DockIcon, FloatIcon } from "./panel-icons";
import { PopOutButton } from "./pop-out";
import { StatusDot } from "./status-dot";

export interface FrameHeadProps {
  panel: OpenPanel;
  block: BlockInfo;
  titleId: string;
  popped: boolean;
  setPopped(popped: boolean): void;
  drag: DragHandlers;
  onClose(): void;
  onUpdate(p: Partial<OpenPanel>): void;
}

export function PanelFrameHead({
  panel,
  block,
  titleId,
  popped,
  setPopped,
  drag,
  onClose,
  onUpdate,
}: FrameHeadProps) {
  return (
    <header
      className="panel-frame__head"
      {...drag}
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
  );
}
