/**
 * What the BlockTable shows over its graph: the "Show the whole pipeline" button, the layout
 * buttons (Auto layout, Save layout…, Write live values…), the legend of status colours and a
 * block's actions menu.
 */
import { ControlButton, Controls, Panel } from "@xyflow/react";
import { useMemo } from "react";
import type { GraphInfo } from "../../engine/protocol";
import type { LiveChange } from "../editor/live-values";
import { describeChanges } from "../editor/live-values";
import { BlockMenu } from "./block-menu";
import { StatusIcon, STATUS_LABEL, type Status } from "./status";
import type { MenuAt } from "./use-block-table";

export function Legend() {
  const order: Status[] = ["ontime", "lagging", "stumbling", "idle"];
  return (
    <ul className="status-legend" aria-label="Status colours">
      {order.map((s) => (
        <li key={s} className={`status-legend__item status-${s}`}>
          <StatusIcon status={s} /> {STATUS_LABEL[s]}
        </li>
      ))}
    </ul>
  );
}

/** The zoom buttons of React Flow, with "Show the whole pipeline" in place of its fit button. */
export function FitControls({ onFit }: { onFit(): void }) {
  return (
    <Controls showInteractive={false} showFitView={false} position="bottom-left">
      <ControlButton
        onClick={onFit}
        title="Show the whole pipeline"
        aria-label="Show the whole pipeline"
      >
        <svg viewBox="0 0 16 16" aria-hidden="true">
          <path
            d="M1.5 5.5v-4h4M10.5 1.5h4v4M14.5 10.5v4h-4M5.5 14.5h-4v-4"
            fill="none"
            stroke="currentColor"
            strokeWidth="1.8"
          />
        </svg>
      </ControlButton>
    </Controls>
  );
}

export function GraphActions({
  canSave,
  changes,
  onAutoLayout,
  onSaveLayout,
  onWriteLiveValues,
}: {
  canSave: boolean;
  /** Live values changed since the pipeline was loaded. */
  changes: LiveChange[];
  onAutoLayout(): void;
  onSaveLayout(): void;
  /** Writes the live values into the file (undefined: cannot). */
  onWriteLiveValues: (() => void) | undefined;
}) {
  return (
    <Panel position="top-right" className="graph-actions">
      <button type="button" onClick={onAutoLayout} title="Arrange the blocks automatically">
        Auto layout
      </button>
      <button
        type="button"
        onClick={onSaveLayout}
        disabled={!canSave}
        title="Download the pipeline file with the blocks' Layout positions updated (comments kept)"
      >
        Save layout…
      </button>
      {changes.length > 0 && onWriteLiveValues ? (
        <button
          type="button"
          className="graph-actions__write-live"
          onClick={onWriteLiveValues}
          title={`Write the live values changed since loading into the pipeline file (comments kept) and download it: ${describeChanges(changes, 10)}`}
        >
          Write live values ({changes.length})…
        </button>
      ) : null}
    </Panel>
  );
}

/** The actions menu of a block, where it was opened (nothing while closed). */
export function TableMenu({
  graph,
  menu,
  openPanels,
  onClose,
  onTogglePanel,
  onInvoke,
}: {
  graph: GraphInfo;
  menu: MenuAt | null;
  openPanels: ReadonlySet<string>;
  onClose(): void;
  onTogglePanel(block: string): void;
  onInvoke(block: string, action: string, arg: unknown, label: string): void;
}) {
  const byName = useMemo(() => new Map(graph.blocks.map((b) => [b.name, b])), [graph]);
  const menuBlock = menu ? byName.get(menu.block) : undefined;
  return menu && menuBlock ? (
    <BlockMenu
      block={menuBlock}
      anchor={menu.anchor}
      panelOpen={openPanels.has(menu.block)}
      onClose={onClose}
      onTogglePanel={() => onTogglePanel(menu.block)}
      onInvoke={(action, arg, label) => onInvoke(menu.block, action, arg, label)}
    />
  ) : null;
}
