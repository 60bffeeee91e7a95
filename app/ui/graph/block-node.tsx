/**
 * One block of the BlockTable: name, type, actual / desired rate, status (colour + icon + word)
 * and the block's one-line text. The node object React Flow holds never changes while the
 * pipeline runs; this component reads its block's telemetry itself and re-renders only when
 * what it shows changed.
 */
import { Handle, Position, type Node, type NodeProps } from "@xyflow/react";
import { createContext, memo, useContext } from "react";
import type { BlockInfo } from "../../engine/protocol";
import type { Telemetry } from "../../engine/runtime/runtime";
import { useLiveBlock, useTelemetrySelector } from "../client/hooks";
import { changedParams } from "../editor/live-values";
import {
  formatRate,
  StatusIcon,
  statusText,
  STATUS_HELP,
  STATUS_LABEL,
  type Status,
} from "./status";

export interface BlockNodeData extends Record<string, unknown> {
  block: BlockInfo;
  /** Edit mode (app/ui/editor): handles connect, the block's problems show on the node. */
  edit?: { issues: string[] };
}
export type BlockNodeType = Node<BlockNodeData, "block">;

/** What the graph around the nodes knows: is the pipeline running, which panels are open. */
export interface GraphState {
  running: boolean;
  openPanels: ReadonlySet<string>;
  onMenu(block: string, anchor: { x: number; y: number }): void;
}
export const GraphStateContext = createContext<GraphState>({
  running: false,
  openPanels: new Set(),
  onMenu: () => {},
});

interface BlockView {
  status: Status;
  stumbling: boolean;
  rate: string;
  text: string;
  errors: number;
  lastError: string;
  dropsIn: number;
  computeMs: string;
}

const IDLE: BlockView = {
  status: "idle",
  stumbling: false,
  rate: "–",
  text: "",
  errors: 0,
  lastError: "",
  dropsIn: 0,
  computeMs: "",
};

function blockView(t: Telemetry | undefined, name: string, running: boolean): BlockView {
  const b = t?.blocks.find((x) => x.name === name);
  if (!b) return IDLE;
  return {
    // Not running: nothing is in operation (grey), whatever the last telemetry said.
    status: running ? b.status : "idle",
    stumbling: running && b.stumbling,
    rate: running && b.status !== "idle" ? formatRate(b.rate) : "–",
    text: b.text,
    errors: b.errors,
    lastError: b.lastError,
    dropsIn: b.dropsIn,
    computeMs: b.computeMeanMs > 0 ? b.computeMeanMs.toFixed(3) : "",
  };
}

/** Rates and compute times show at most 4 times a second; everything else at once. */
const HOLD = {
  ms: 250,
  urgent: (a: BlockView, b: BlockView): boolean =>
    a.status !== b.status ||
    a.stumbling !== b.stumbling ||
    a.text !== b.text ||
    a.errors !== b.errors ||
    a.lastError !== b.lastError ||
    a.dropsIn !== b.dropsIn ||
    (a.rate === "–") !== (b.rate === "–"),
};

function BlockNodeComponent({ data }: NodeProps<BlockNodeType>) {
  const b = data.block;
  const edit = data.edit;
  const g = useContext(GraphStateContext);
  const v = useTelemetrySelector((t) => blockView(t, b.name, g.running), undefined, HOLD);
  const both = v.status === "lagging" && v.stumbling;
  const label = statusText(v.status, v.stumbling);
  const desired =
    b.desiredRate > 0
      ? Number.isInteger(b.desiredRate)
        ? String(b.desiredRate)
        : formatRate(b.desiredRate)
      : "–";
  const open = g.openPanels.has(b.name);
  const title =
    `${b.name} (${b.type}): ${STATUS_HELP[v.status]}` +
    (both ? "; also stumbling" : "") +
    (v.computeMs ? `\ncompute ${v.computeMs} ms per call (mean)` : "") +
    (b.summary ? `\n${b.summary}` : "") +
    "\nClick or Enter: control panel · right-click or Shift+F10: actions";
  return (
    <div
      className={
        `block-node status-${v.status}` +
        (both ? " also-stumbling" : "") +
        (open ? " panel-open" : "") +
        (v.errors > 0 ? " has-errors" : "") +
        (edit ? " is-editing" : "") +
        (edit && edit.issues.length > 0 ? " has-issues" : "")
      }
      data-block={b.name}
      data-status={v.status}
      data-stumbling={String(v.stumbling)}
      data-issues={edit ? String(edit.issues.length) : undefined}
      title={edit ? `${b.name} (${b.type})${b.summary ? `\n${b.summary}` : ""}` : title}
    >
      <Handle
        type="target"
        position={Position.Left}
        isConnectable={edit !== undefined}
        aria-label={edit ? `inputs of ${b.name}` : undefined}
        className={b.inputs.length === 0 && !edit ? "handle-unused" : ""}
      />
      <div className="block-node__head">
        <span className="block-node__name">{b.name}</span>
        {edit ? null : (
          <button
            type="button"
            className="block-node__menu nodrag"
            tabIndex={-1}
            aria-label={`Actions of ${b.name}`}
            onClick={(e) => {
              e.stopPropagation();
              const r = e.currentTarget.getBoundingClientRect();
              g.onMenu(b.name, { x: r.left, y: r.bottom + 2 });
            }}
          >
            ⋮
          </button>
        )}
      </div>
      <div className="block-node__type">
        {b.type} <ChangedMark block={b} />
      </div>
      <div className="block-node__status" aria-label={`status: ${label}`}>
        <span className="block-node__status-item">
          <StatusIcon status={v.status} />
          {STATUS_LABEL[v.status]}
        </span>
        {both ? (
          <span className="block-node__status-item is-also">
            <StatusIcon status="stumbling" />
            stumbling
          </span>
        ) : null}
      </div>
      <div className="block-node__rate" aria-label={`rate ${v.rate} of ${desired} hertz`}>
        {v.rate} / {desired} Hz
      </div>
      {v.text !== "" || v.errors > 0 || v.dropsIn > 0 ? (
        <div className="block-node__text">
          {v.errors > 0 ? (
            <span className="block-node__errors" title={v.lastError}>
              {v.errors} error{v.errors === 1 ? "" : "s"}
            </span>
          ) : null}
          {v.dropsIn > 0 ? <span className="block-node__drops">{v.dropsIn} dropped</span> : null}
          <span className="block-node__note">{v.errors > 0 ? v.lastError : v.text}</span>
        </div>
      ) : null}
      {edit && edit.issues.length > 0 ? (
        <ul className="block-node__issues">
          {edit.issues.map((m, i) => (
            <li key={i}>{m}</li>
          ))}
        </ul>
      ) : null}
      <Handle
        type="source"
        position={Position.Right}
        isConnectable={edit !== undefined}
        aria-label={edit ? `output of ${b.name}` : undefined}
      />
    </div>
  );
}

/**
 * "changed": live params the engine runs with values other than the file's (issue 17, defect 1).
 * Memoised: it renders when its block's params change, not with the node's telemetry.
 */
const ChangedMark = memo(function ChangedMark({ block }: { block: BlockInfo }) {
  const live = useLiveBlock(block);
  const changed = changedParams(live);
  if (changed.length === 0) return null;
  const list = changed
    .map(
      (p) =>
        `${p} = ${JSON.stringify(live.params[p])} (file: ${JSON.stringify(live.fileParams?.[p])})`,
    )
    .join("\n");
  return (
    <span
      className="block-node__changed"
      data-changed={changed.join(",")}
      title={`Changed since loaded:\n${list}`}
      aria-label={`${changed.length} live value${changed.length === 1 ? "" : "s"} changed since loaded`}
    >
      changed
    </span>
  );
});

export const BlockNode = memo(BlockNodeComponent);
