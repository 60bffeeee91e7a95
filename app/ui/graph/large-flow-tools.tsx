/**
 * What a large pipeline needs on the BlockTable (issue 17, "large flows"): a minimap (click or
 * drag in it to move the view), finding a block by name (block-search.tsx), and group and comment
 * boxes (box-layer.tsx) added here and saved into the file's `Pipeline: { Layout }` by
 * "Save layout…". Rendered inside the BlockTable's <ReactFlow>.
 */
import { MiniMap, Panel, useReactFlow } from "@xyflow/react";
import { BlockSearch } from "./block-search";
import { BoxLayer, type BoxLayerProps } from "./box-layer";
import { newBox, type BoxKind } from "./boxes";
import "./graph-tools.css";

export interface LargeFlowToolsProps extends BoxLayerProps {
  names: readonly string[];
  /** Animation of view changes, ms (0 with reduced motion). */
  duration: number;
}

function Minimap({ duration }: { duration: number }) {
  const flow = useReactFlow();
  return (
    <MiniMap
      className="graph-minimap"
      position="bottom-left"
      pannable
      zoomable
      ariaLabel="Minimap of the pipeline: click or drag to move the view"
      nodeStrokeWidth={3}
      // Linear: the view slides there at the same zoom (the default smooth path zooms out on
      // the way and back in, so a click seemed to change the zoom while the view moved).
      onClick={(_e, p) =>
        void flow.setCenter(p.x, p.y, { zoom: flow.getZoom(), duration, interpolate: "linear" })
      }
    />
  );
}

function AddBoxes({ layer }: { layer: BoxLayerProps }) {
  const flow = useReactFlow();
  const add = (kind: BoxKind, e: React.MouseEvent<HTMLButtonElement>): void => {
    // At the top left of the view, under these buttons (where a fitted pipeline leaves room),
    // each new one a little lower and to the right of the one before.
    const graph = e.currentTarget.closest(".block-table")?.getBoundingClientRect();
    const { boxes } = layer;
    const step = 24 * ((boxes.groups.length + boxes.comments.length) % 6);
    const at = graph
      ? flow.screenToFlowPosition({ x: graph.x + 24 + step, y: graph.y + 80 + step })
      : { x: 0, y: 0 };
    const box = newBox(kind, at);
    layer.onBoxes(
      kind === "group"
        ? {
            ...boxes,
            groups: [...boxes.groups, { title: `Group ${boxes.groups.length + 1}`, ...box }],
          }
        : { ...boxes, comments: [...boxes.comments, { text: "Comment", ...box }] },
    );
  };
  return (
    <>
      <button
        type="button"
        onClick={(e) => add("group", e)}
        title="A titled box: the blocks inside it move with it"
      >
        + Group
      </button>
      <button type="button" onClick={(e) => add("comment", e)} title="A box of text on the canvas">
        + Comment
      </button>
    </>
  );
}

export function LargeFlowTools(props: LargeFlowToolsProps) {
  return (
    <>
      <Panel position="top-left" className="graph-tools">
        <BlockSearch names={props.names} duration={props.duration} />
        <AddBoxes layer={props} />
      </Panel>
      <Minimap duration={props.duration} />
      <BoxLayer boxes={props.boxes} onBoxes={props.onBoxes} onBlocksMoved={props.onBlocksMoved} />
    </>
  );
}
