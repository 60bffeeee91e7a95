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

/** The desired rate as shown: a whole number as it is, else like a rate; "–" when it has none. */
function desiredRateText(rate: number): string {
  return rate > 0 ? (Number.isInteger(rate) ? String(rate) : formatRate(rate)) : "–";
}

/** The node's tooltip: in edit mode name, type and summary; else also status and help. */
function nodeTitle(b: BlockInfo, v: BlockView, both: boolean, edit: BlockNodeData["edit"]): string {
  if (edit) return `${b.name} (${b.type})${b.summary ? `\n${b.summary}` : ""}`;
  return (
    `${b.name} (${b.type}): ${STATUS_HELP[v.status]}` +
    (both ? "; also stumbling" : "") +
    (v.computeMs ? `\ncompute ${v.computeMs} ms per call (mean)` : "") +
    (b.summary ? `\n${b.summary}` : "") +
    "\nClick or Enter: control panel · right-click or Shift+F10: actions"
  );
}

/** The node's class names: its status and what else shows on it. */
function nodeClass(
  v: BlockView,
  both: boolean,
  open: boolean,
  edit: BlockNodeData["edit"],
): string {
  return (
    `block-node status-${v.status}` +
    (both ? " also-stumbling" : "") +
    (open ? " panel-open" : "") +
    (v.errors > 0 ? " has-errors" : "") +
    (edit ? " is-editing" : "") +
    (edit && edit.issues.length > 0 ? " has-issues" : "")
  );
}

/** The graph state and what the node shows of its block's telemetry. */
function useBlockNode(b: BlockInfo) {
  const g = useContext(GraphStateContext);
  const v = useTelemetrySelector((t) => blockView(t, b.name, g.running), undefined, HOLD);
  /** Lagging and stumbling at once: both show. */
  const both = v.status === "lagging" && v.stumbling;
  return { g, v, both };
}

/** One block's node: its handles, name and menu, type, status, rate, text and issues. */
function BlockNodeComponent({ data }: NodeProps<BlockNodeType>) {
  const b = data.block;
  const edit = data.edit;
  const { g, v, both } = useBlockNode(b);
  const desired = desiredRateText(b.desiredRate);
  return (
    <div
      className={nodeClass(v, both, g.openPanels.has(b.name), edit)}
      data-block={b.name}
      data-status={v.status}
      data-stumbling={String(v.stumbling)}
      data-issues={edit ? String(edit.issues.length) : undefined}
      title={nodeTitle(b, v, both, edit)}
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
        {edit ? null : <MenuButton name={b.name} onMenu={g.onMenu} />}
      </div>
      <div className="block-node__type">
        {b.type} <ChangedMark block={b} />
      </div>
      <NodeStatus v={v} both={both} />
      <div className="block-node__rate" aria-label={`rate ${v.rate} of ${desired} hertz`}>
        {v.rate} / {desired} Hz
      </div>
      {v.text !== "" || v.errors > 0 || v.dropsIn > 0 ? <NodeText v={v} /> : null}
      {edit && edit.issues.length > 0 ? <NodeIssues issues={edit.issues} /> : null}
      <Handle
        type="source"
        position={Position.Right}
        isConnectable={edit !== undefined}
        aria-label={edit ? `output of ${b.name}` : undefined}
      />
    </div>
  );
}

/** ⋮: opens the block's actions below itself (the click does not reach the node). */
function MenuButton({ name, onMenu }: { name: string; onMenu: GraphState["onMenu"] }) {
  return (
    <button
      type="button"
      className="block-node__menu nodrag"
      tabIndex={-1}
      aria-label={`Actions of ${name}`}
      onClick={(e) => {
        e.stopPropagation();
        const r = e.currentTarget.getBoundingClientRect();
        onMenu(name, { x: r.left, y: r.bottom + 2 });
      }}
    >
      ⋮
    </button>
  );
}

/** Status: icon and word, and "stumbling" beside it when the block is lagging too. */
function NodeStatus({ v, both }: { v: BlockView; both: boolean }) {
  return (
    <div className="block-node__status" aria-label={`status: ${statusText(v.status, v.stumbling)}`}>
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
  );
}

/** Errors (the last one's text), dropped inputs, and the block's one-line text. */
function NodeText({ v }: { v: BlockView }) {
  return (
    <div className="block-node__text">
      {v.errors > 0 ? (
        <span className="block-node__errors" title={v.lastError}>
          {v.errors} error{v.errors === 1 ? "" : "s"}
        </span>
      ) : null}
      {v.dropsIn > 0 ? <span className="block-node__drops">{v.dropsIn} dropped</span> : null}
      <span className="block-node__note">{v.errors > 0 ? v.lastError : v.text}</span>
    </div>
  );
}

/** Edit mode: the block's problems. */
function NodeIssues({ issues }: { issues: string[] }) {
  return (
    <ul className="block-node__issues">
      {issues.map((m, i) => (
        <li key={i}>{m}</li>
      ))}
    </ul>
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
