/**
 * A predictor's Training view (issue 17): its status, its model file (save, or load from a file
 * picked in the page), prediction versus target per output, R² per output over the recent
 * labelled samples and, when the targets are gestures (one-hot, as a Stimulus or a Trigger cues
 * them), the accuracy per gesture and the confusion matrix. The figures come from the block's
 * `versus` output, watched only while the view is open; below, the block's own fit (its `fit`
 * output: samples or rows learnt and R² per output since training began, or of the last batch
 * fit), for every predictor.
 */
import { useCallback, useMemo, useState, type ReactNode } from "react";
import type { BlockInfo, DataMessage } from "../../engine/protocol";
import { useBlockData, useGraph } from "../client/hooks";
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
  const fit = block.outputs.find((o) => o.name === "fit");
  const m = versus
    ? (versus.shape.rows * versus.shape.cols) / 2
    : fit
      ? fit.shape.rows * fit.shape.cols - 1
      : 0;
  const names = useMemo(() => predictorOutputNames(block, graph, m), [block, graph, m]);
  return (
    <div className="mp-training" data-view="training" data-block={block.name}>
      <StatusText block={block.name} />
      <ModelFileControls block={block} />
      {versus && m > 0 ? (
        <Feedback key={m} block={block.name} m={m} names={names} active={active} />
      ) : (
        <p className="mp-muted">
          This block learns in batches: no prediction versus target per sample.
        </p>
      )}
      {fit && m > 0 && <FitFigures block={block.name} names={names} active={active} />}
    </div>
  );
}

/** The block's own fit output, latest event: [samples or rows, R² of each output]. */
function FitFigures({
  block,
  names,
  active,
}: {
  block: string;
  names: string[];
  active: boolean;
}): ReactNode {
  const [latest, setLatest] = useState<Float64Array | null>(null);
  const onData = useCallback((msg: DataMessage) => {
    const n = msg.t.length;
    const w = msg.rows * msg.cols;
    if (n > 0) setLatest(msg.v.slice((n - 1) * w, n * w));
  }, []);
  useBlockData(block, "fit", onData, active, 4);
  if (!latest) return <p className="mp-muted">No fit reported yet.</p>;
  return (
    <section aria-label="Fit since training began">
      <p className="mp-muted" data-fit-samples={latest[0]}>
        The block&apos;s own fit: learnt from {latest[0]} samples
      </p>
      <R2Table
        r2={latest.subarray(1)}
        names={names}
        label="R² per output (the block's fit)"
        className="mp-fit"
      />
    </section>
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
        <R2Table r2={s.r2} names={names} label="R² per output (recent samples)" />
      ) : (
        <p className="mp-muted">
          {active ? "No sample learnt yet: R² shows once targets arrive." : "hidden"}
        </p>
      )}
      {s.classes && <GestureFigures classes={s.classes} names={names} />}
    </>
  );
}
