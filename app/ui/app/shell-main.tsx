/**
 * The app shell's main area and notices: the editor in edit mode; else the problems of a file
 * that was not loaded, the warnings of the one that was, and the BlockTable with the control
 * panels (or the diagnostics of a pipeline that does not load, or why there is nothing).
 */
import { useState } from "react";
import type { GraphInfo } from "../../engine/protocol";
import type { ConnectionLoss } from "../client/connection-status";
import { useEngine } from "../client/hooks";
import { BlockTable } from "../graph/block-table";
import { Editor } from "../editor/editor";
import { Diagnostics } from "./diagnostics";
import { ConnectionLost } from "./engine-badge";
import { EventLog } from "./event-log";
import { GestureLegend, type GestureResult } from "./gestures";
import { PanelHost, type EditStatic } from "./panel-host";
import { shortName } from "./pipeline-picker";
import type { EditMode } from "./use-edit-mode";
import type { EventLogState } from "./use-event-log";
import type { Notice, Notify } from "./use-notice";
import type { ShellPanels } from "./use-shell-panels";
import type { Pipeline } from "./use-shell-state";

function ShellEditor({
  pipeline,
  running,
  edit,
}: {
  pipeline: Pipeline;
  running: boolean;
  edit: EditMode;
}) {
  const client = useEngine();
  return (
    <Editor
      client={client}
      initialText={edit.text}
      initialFile={edit.file}
      appliedText={pipeline.source}
      templates={pipeline.index}
      graph={pipeline.graph}
      running={running}
      applying={edit.applying}
      onApply={edit.apply}
      onNotify={edit.notify}
      onDraft={edit.onDraft}
      onClose={edit.leave}
    />
  );
}

/** The problems of a file that was not loaded, while the one before goes on. */
function RejectedBanner({ pipeline, running }: { pipeline: Pipeline; running: boolean }) {
  if (pipeline.graph === undefined || !pipeline.rejected) return null;
  return (
    <div className="warnings-banner rejected-banner" data-rejected={pipeline.rejected.file}>
      <p>
        <strong>{shortName(pipeline.rejected.file)}</strong> was not loaded:{" "}
        <strong>{shortName(pipeline.file ?? "")}</strong> goes on {running ? "running" : "loaded"}.
      </p>
      <Diagnostics
        diagnostics={pipeline.rejected.diagnostics}
        error={pipeline.rejected.error}
        failed
      />
      <button
        type="button"
        aria-label="Dismiss the problems of the file that was not loaded"
        onClick={pipeline.dismissRejected}
      >
        ×
      </button>
    </div>
  );
}

/** The warnings of the loaded pipeline, until dismissed (for this load). */
function WarningsBanner({
  pipeline,
  hidden,
  onDismiss,
}: {
  pipeline: Pipeline;
  /** The load (generation) whose warnings were dismissed. */
  hidden: number;
  onDismiss(generation: number): void;
}) {
  if (
    pipeline.graph === undefined ||
    pipeline.diagnostics.length === 0 ||
    hidden === pipeline.generation
  )
    return null;
  return (
    <div className="warnings-banner">
      <Diagnostics diagnostics={pipeline.diagnostics} error={undefined} failed={false} />
      <button
        type="button"
        aria-label="Dismiss the warnings"
        onClick={() => onDismiss(pipeline.generation)}
      >
        ×
      </button>
    </div>
  );
}

interface ContentProps {
  pipeline: Pipeline;
  running: boolean;
  loss: ConnectionLoss | undefined;
  panels: ShellPanels;
  editStatic: EditStatic;
  positions: Map<string, { x: number; y: number }>;
  reducedMotion: boolean;
  invoke(block: string, action: string, arg: unknown, label: string): void;
  notify: Notify;
}

/** The BlockTable under the control panels, or why there is none. */
function PipelineContent({
  pipeline,
  running,
  loss,
  panels,
  editStatic,
  positions,
  reducedMotion,
  invoke,
  notify,
}: ContentProps) {
  const { graph } = pipeline;
  const failed = graph === undefined && !pipeline.loading && pipeline.file !== undefined;
  return graph !== undefined ? (
    <PanelHost
      panels={panels.panels}
      blocks={panels.blocks}
      onEditStatic={editStatic}
      onClose={panels.ui.closePanel}
      onUpdate={panels.onUpdate}
      onRaise={panels.onRaise}
    >
      <BlockTable
        key={pipeline.generation}
        graph={graph}
        source={pipeline.source}
        positions={positions}
        running={running}
        openPanels={panels.openSet}
        reducedMotion={reducedMotion}
        onTogglePanel={panels.ui.togglePanel}
        onInvoke={invoke}
        onNotify={(m, level) => notify(m, level)}
      />
    </PanelHost>
  ) : failed ? (
    <Diagnostics diagnostics={pipeline.diagnostics} error={pipeline.error} failed />
  ) : loss ? null : (
    <p className="main__empty">
      {pipeline.loading ? "Loading the pipeline…" : "No pipeline loaded."}
    </p>
  );
}

/**
 * The main area: the editor in edit mode, else the banners and the pipeline. Warnings dismissed
 * stay dismissed (for that load) across edit mode.
 */
export function ShellMain(props: ContentProps & { edit: EditMode }) {
  const { pipeline, running, loss, edit } = props;
  const [warningsHidden, setWarningsHidden] = useState(-1);
  return (
    <main className="main">
      {loss ? <ConnectionLost loss={loss} /> : null}
      {edit.editing ? (
        <ShellEditor pipeline={pipeline} running={running} edit={edit} />
      ) : (
        <>
          <RejectedBanner pipeline={pipeline} running={running} />
          <WarningsBanner
            pipeline={pipeline}
            hidden={warningsHidden}
            onDismiss={setWarningsHidden}
          />
          <PipelineContent {...props} />
        </>
      )}
    </main>
  );
}

/** The gesture keys of simulated EMG and the event log. */
export function ShellFooter({
  graph,
  log,
  onGesture,
}: {
  graph: GraphInfo | undefined;
  log: EventLogState;
  onGesture: GestureResult;
}) {
  return (
    <footer className="footer">
      <GestureLegend graph={graph} onResult={onGesture} />
      <EventLog
        book={log.book}
        open={log.open}
        onToggle={() => log.setOpen((o) => !o)}
        onClear={log.clear}
      />
    </footer>
  );
}

export function NoticeLine({ notice }: { notice: Notice | null }) {
  return (
    <div
      className={`notice${notice ? ` is-shown level-${notice.level}` : ""}`}
      role="status"
      aria-live="polite"
    >
      {notice?.text ?? ""}
    </div>
  );
}
