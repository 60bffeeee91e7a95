/**
 * An input reference of the BlockTable (`Block.port` → consumer): labelled with the source's
 * actual rate; dashed and grey when unsubscribed; red when the source lags, magenta when it
 * stumbles; a drop counter when events were dropped on it. Reads its telemetry itself, like the
 * nodes, so the edge objects React Flow holds never change while running.
 */
import {
  BaseEdge,
  EdgeLabelRenderer,
  getBezierPath,
  type Edge,
  type EdgeProps,
} from "@xyflow/react";
import { memo, useContext } from "react";
import type { Telemetry } from "../../engine/runtime/runtime";
import { useTelemetrySelector } from "../client/hooks";
import { GraphStateContext } from "./block-node";
import { formatRate } from "./status";

export interface RateEdgeData extends Record<string, unknown> {
  from: string;
  port: string;
  /** Shown in the label when it is not the source's first (default) output. */
  showPort: boolean;
  to: string;
  toIndex: number;
  /** As declared in the file (`-Name` is unsubscribed). */
  subscribed: boolean;
}
export type RateEdgeType = Edge<RateEdgeData, "rate">;

type EdgeState = "ok" | "lagging" | "stumbling" | "off" | "idle";

interface EdgeView {
  subscribed: boolean;
  state: EdgeState;
  rate: string;
  dropped: number;
}

function edgeView(t: Telemetry | undefined, d: RateEdgeData, running: boolean): EdgeView {
  const e = t?.edges.find((x) => x.to === d.to && x.toIndex === d.toIndex);
  const subscribed = e ? e.subscribed : d.subscribed;
  const src = t?.blocks.find((b) => b.name === d.from);
  let state: EdgeState = "idle";
  if (!subscribed) state = "off";
  else if (running && src) {
    state = src.lagging
      ? "lagging"
      : src.stumbling
        ? "stumbling"
        : src.status === "idle"
          ? "idle"
          : "ok";
  }
  return {
    subscribed,
    state,
    rate: running && src && src.status !== "idle" ? formatRate(src.rate) : "–",
    dropped: e?.dropped ?? 0,
  };
}

export const EDGE_MARKERS: EdgeState[] = ["ok", "lagging", "stumbling", "off", "idle"];

/** Arrow heads, one per edge state (referenced by id from every edge path). */
export function EdgeMarkerDefs() {
  return (
    <svg className="edge-markers" aria-hidden="true" width="0" height="0">
      <defs>
        {EDGE_MARKERS.map((s) => (
          <marker
            key={s}
            id={`mosaic-arrow-${s}`}
            viewBox="0 0 10 10"
            refX="9"
            refY="5"
            markerUnits="userSpaceOnUse"
            markerWidth="11"
            markerHeight="11"
            orient="auto-start-reverse"
          >
            <path d="M0,0 L10,5 L0,10 z" className={`edge-arrow edge-arrow--${s}`} />
          </marker>
        ))}
      </defs>
    </svg>
  );
}

/** The rate label changes at most 4 times a second; a new state or drop count at once. */
const HOLD = {
  ms: 250,
  urgent: (a: EdgeView, b: EdgeView): boolean =>
    a.state !== b.state ||
    a.subscribed !== b.subscribed ||
    a.dropped !== b.dropped ||
    (a.rate === "–") !== (b.rate === "–"),
};

function RateEdgeComponent(props: EdgeProps<RateEdgeType>) {
  const { sourceX, sourceY, targetX, targetY, sourcePosition, targetPosition, data } = props;
  const g = useContext(GraphStateContext);
  const d = data!;
  const v = useTelemetrySelector((t) => edgeView(t, d, g.running), undefined, HOLD);
  const [path, labelX, labelY] = getBezierPath({
    sourceX,
    sourceY,
    targetX,
    targetY,
    sourcePosition,
    targetPosition,
  });
  const name = `${d.from}->${d.to}`;
  const describe =
    `${d.from}${d.showPort ? `.${d.port}` : ""} → ${d.to}: ` +
    (v.subscribed ? `${v.rate} Hz` : "unsubscribed") +
    (v.dropped > 0 ? `, ${v.dropped} dropped` : "");
  return (
    <g
      className={`rate-edge rate-edge--${v.state}`}
      data-edge={name}
      data-subscribed={String(v.subscribed)}
      data-state={v.state}
    >
      <title>{describe}</title>
      <BaseEdge path={path} markerEnd={`url(#mosaic-arrow-${v.state})`} />
      <EdgeLabelRenderer>
        <div
          className={`rate-edge__label rate-edge__label--${v.state}`}
          data-edge-label={name}
          style={{ transform: `translate(-50%, -50%) translate(${labelX}px, ${labelY}px)` }}
          title={describe}
        >
          {d.showPort ? <span className="rate-edge__port">{d.port}</span> : null}
          {!v.subscribed ? (
            <span aria-label="unsubscribed">off</span>
          ) : (
            <span>{v.rate === "–" ? "–" : `${v.rate} Hz`}</span>
          )}
          {v.dropped > 0 ? (
            <span className="rate-edge__drops" aria-label={`${v.dropped} events dropped`}>
              ⚠ {v.dropped} dropped
            </span>
          ) : null}
        </div>
      </EdgeLabelRenderer>
    </g>
  );
}

export const RateEdge = memo(RateEdgeComponent);
