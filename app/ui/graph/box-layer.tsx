/**
 * Group and comment boxes drawn on the BlockTable's canvas (in React Flow's viewport portal, so
 * they pan and zoom with the graph). A group is a dashed outline with a title tab above it; the
 * blocks inside show through and take clicks as usual. A box moves by its title tab (a group
 * takes the blocks inside it along) or, for a comment, its text; it resizes by its corner, is
 * renamed or edited by a double click (or its ✎ button) and removed by its × button.
 * Model: boxes.ts.
 */
import { ViewportPortal, useReactFlow } from "@xyflow/react";
import { useRef, useState, type ReactNode } from "react";
import type { LayoutBox } from "../../engine/pipeline/pipeline-layout";
import { MIN_BOX, nodesInside, removeBox, updateBox, type BoxKind, type Boxes } from "./boxes";
import "./graph-tools.css";

export interface BoxLayerProps {
  boxes: Boxes;
  onBoxes(next: Boxes): void;
  /** Blocks a group carried along, with their new positions (on release). */
  onBlocksMoved(moved: ReadonlyMap<string, { x: number; y: number }>): void;
}

type Gesture = "move" | "resize";

/** Pointer drags of a box's title bar (move) or corner (resize), in canvas pixels. */
function useBoxDrag(props: BoxLayerProps, kind: BoxKind, i: number, box: LayoutBox) {
  const flow = useReactFlow();
  const start = useRef<{
    gesture: Gesture;
    px: number;
    py: number;
    box: LayoutBox;
    carried: Map<string, { x: number; y: number }>;
    moved: Map<string, { x: number; y: number }>;
  } | null>(null);

  const onPointerDown = (gesture: Gesture) => (e: React.PointerEvent<HTMLElement>) => {
    if (e.button !== 0 || (e.target as HTMLElement).closest("button, input, textarea")) return;
    e.stopPropagation();
    e.currentTarget.setPointerCapture(e.pointerId);
    const carried = new Map<string, { x: number; y: number }>();
    if (kind === "group" && gesture === "move") {
      const rects = flow.getNodes().map((n) => ({
        id: n.id,
        ...n.position,
        width: n.measured?.width ?? 0,
        height: n.measured?.height ?? 0,
      }));
      for (const id of nodesInside(box, rects)) carried.set(id, flow.getNode(id)!.position);
    }
    start.current = { gesture, px: e.clientX, py: e.clientY, box, carried, moved: new Map() };
  };
  const onPointerMove = (e: React.PointerEvent<HTMLElement>) => {
    const s = start.current;
    if (!s) return;
    const zoom = flow.getZoom();
    const dx = (e.clientX - s.px) / zoom;
    const dy = (e.clientY - s.py) / zoom;
    if (s.gesture === "resize") {
      const width = Math.max(MIN_BOX.width, s.box.width + dx);
      const height = Math.max(MIN_BOX.height, s.box.height + dy);
      props.onBoxes(updateBox(props.boxes, kind, i, () => ({ width, height })));
      return;
    }
    props.onBoxes(updateBox(props.boxes, kind, i, () => ({ x: s.box.x + dx, y: s.box.y + dy })));
    if (s.carried.size === 0) return;
    for (const [id, p] of s.carried) s.moved.set(id, { x: p.x + dx, y: p.y + dy });
    flow.setNodes((ns) =>
      ns.map((n) => (s.moved.has(n.id) ? { ...n, position: s.moved.get(n.id)! } : n)),
    );
  };
  const onPointerUp = () => {
    const s = start.current;
    start.current = null;
    if (s && s.moved.size > 0) props.onBlocksMoved(s.moved);
  };
  const handlers = { onPointerMove, onPointerUp, onPointerCancel: onPointerUp };
  return {
    head: { onPointerDown: onPointerDown("move"), ...handlers },
    corner: { onPointerDown: onPointerDown("resize"), ...handlers },
  };
}

/** A line (group title) or text (comment) edited in place; Enter (Ctrl+Enter in text) keeps it. */
function InlineEdit(props: {
  value: string;
  multiline: boolean;
  label: string;
  onDone(value: string | undefined): void;
}) {
  const [v, setV] = useState(props.value);
  const keep = (e: React.KeyboardEvent) => {
    if (e.key === "Escape") props.onDone(undefined);
    else if (e.key === "Enter" && (!props.multiline || e.ctrlKey || e.metaKey)) props.onDone(v);
    else return;
    e.preventDefault();
    e.stopPropagation();
  };
  const common = {
    className: "graph-box__edit nodrag nopan nowheel",
    value: v,
    autoFocus: true,
    "aria-label": props.label,
    onKeyDown: keep,
    onBlur: () => props.onDone(v),
  };
  return props.multiline ? (
    <textarea {...common} onChange={(e) => setV(e.target.value)} />
  ) : (
    <input {...common} onChange={(e) => setV(e.target.value)} />
  );
}

function BoxButtons(props: { what: string; onEdit(): void; onRemove(): void }) {
  return (
    <span className="graph-box__buttons">
      <button type="button" onClick={props.onEdit} aria-label={`Edit ${props.what}`} title="Edit">
        ✎
      </button>
      <button
        type="button"
        onClick={props.onRemove}
        aria-label={`Remove ${props.what}`}
        title="Remove (the blocks stay)"
      >
        ×
      </button>
    </span>
  );
}

function BoxFrame(props: {
  layer: BoxLayerProps;
  kind: BoxKind;
  i: number;
  box: LayoutBox;
  label: string;
  children: (editing: boolean, stop: () => void) => ReactNode;
}) {
  const { layer, kind, i, box, label } = props;
  const drag = useBoxDrag(layer, kind, i, box);
  const [editing, setEditing] = useState(false);
  const what = kind === "group" ? `group ${label}` : "comment";
  return (
    <div
      className={`graph-box graph-box--${kind}`}
      style={{ left: box.x, top: box.y, width: box.width, height: box.height }}
      data-box={kind}
      data-index={i}
      data-label={label}
    >
      <div
        className="graph-box__head nopan nodrag"
        {...drag.head}
        onDoubleClick={() => setEditing(true)}
      >
        {props.children(editing, () => setEditing(false))}
        <BoxButtons
          what={what}
          onEdit={() => setEditing(true)}
          onRemove={() => layer.onBoxes(removeBox(layer.boxes, kind, i))}
        />
      </div>
      <div
        className="graph-box__corner nopan nodrag"
        {...drag.corner}
        aria-hidden="true"
        title="Drag to resize"
      />
    </div>
  );
}

function GroupBox({ layer, i }: { layer: BoxLayerProps; i: number }) {
  const g = layer.boxes.groups[i]!;
  return (
    <BoxFrame layer={layer} kind="group" i={i} box={g} label={g.title}>
      {(editing, stop) =>
        editing ? (
          <InlineEdit
            value={g.title}
            multiline={false}
            label="Group title"
            onDone={(v) => {
              stop();
              if (v !== undefined)
                layer.onBoxes(updateBox(layer.boxes, "group", i, () => ({ title: v })));
            }}
          />
        ) : (
          <span className="graph-box__title">{g.title || "Group"}</span>
        )
      }
    </BoxFrame>
  );
}

function CommentBox({ layer, i }: { layer: BoxLayerProps; i: number }) {
  const c = layer.boxes.comments[i]!;
  return (
    <BoxFrame layer={layer} kind="comment" i={i} box={c} label={c.text}>
      {(editing, stop) =>
        editing ? (
          <InlineEdit
            value={c.text}
            multiline
            label="Comment text (Ctrl+Enter to keep)"
            onDone={(v) => {
              stop();
              if (v !== undefined)
                layer.onBoxes(updateBox(layer.boxes, "comment", i, () => ({ text: v })));
            }}
          />
        ) : (
          <p className="graph-box__text">{c.text || "Comment"}</p>
        )
      }
    </BoxFrame>
  );
}

/** Every box of the pipeline, in the canvas's coordinates. */
export function BoxLayer(props: BoxLayerProps) {
  return (
    <ViewportPortal>
      <div className="graph-boxes">
        {props.boxes.groups.map((_, i) => (
          <GroupBox key={`g${i}`} layer={props} i={i} />
        ))}
        {props.boxes.comments.map((_, i) => (
          <CommentBox key={`c${i}`} layer={props} i={i} />
        ))}
      </div>
    </ViewportPortal>
  );
}
