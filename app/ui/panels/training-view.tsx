/**
 * A predictor's Training view (issue 17): its status, its model file (save, or load from a file
 * picked in the page), prediction versus target per output, R² per output over the recent
 * labelled samples and, when the targets are gestures (one-hot, as a Stimulus or a Trigger cues
 * them), the accuracy per gesture and the confusion matrix. The figures come from the block's
 * `versus` output, watched only while the view is open.
 */
import { useMemo, type ReactNode } from "react";
import type { BlockInfo } from "../../engine/protocol";
import { useGraph } from "../client/hooks";
import { StatusText } from "./labels";
import { ModelFileControls } from "./model-file-controls";
import { useTrainingFeed, WINDOW_SAMPLES } from "./training-feed";
import { predictorOutputNames } from "./training-names";
import { VersusOverlay } from "./training-overlay";
import { GestureFigures, R2Table } from "./training-tables";
import "./training.css";

export function TrainingView({ block, active }: { block: BlockInfo; active: boolean }): ReactNode {
  const graph = useGraph();
  const versus = block.outputs.find((o) => o.name === "versus");
  const m = versus ? (versus.shape.rows * versus.shape.cols) / 2 : 0;
  const names = useMemo(() => predictorOutputNames(block, graph, m), [block, graph, m]);
  return (
    <div className="mp-training" data-view="training" data-block={block.name}>
      <StatusText block={block.name} />
      <ModelFileControls block={block} />
      {m > 0 ? (
        <Feedback key={m} block={block.name} m={m} names={names} active={active} />
      ) : (
        <p className="mp-muted">
          This block reports no prediction versus target: see its fit output and status.
        </p>
      )}
    </div>
  );
}

function Feedback({
  block,
  m,
  names,
  active,
}: {
  block: string;
  m: number;
  names: string[];
  active: boolean;
}): ReactNode {
  const feed = useTrainingFeed(block, m, active);
  const s = feed.summary;
  return (
    <>
      <div className="mp-toolbar">
        <span className="mp-muted" data-samples={s.samples}>
          {s.samples} labelled {s.samples === 1 ? "sample" : "samples"} (the last {WINDOW_SAMPLES}{" "}
          count)
        </span>
        <button type="button" className="mp-btn" onClick={feed.clear}>
          Reset figures
        </button>
      </div>
      <VersusOverlay traces={feed.traces} names={names} />
      {s.samples > 0 ? (
        <R2Table summary={s} names={names} />
      ) : (
        <p className="mp-muted">
          {active ? "No sample learnt yet: R² shows once targets arrive." : "hidden"}
        </p>
      )}
      {s.classes && <GestureFigures classes={s.classes} names={names} />}
    </>
  );
}
