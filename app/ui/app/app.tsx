/**
 * The app shell: toolbar (pipeline picker, load, start/stop, engine state, timing precision),
 * the BlockTable with the control panels (docked or floating), the gesture keys of simulated EMG,
 * the diagnostics of a pipeline that does not load and the log of runtime events. Works with any
 * engine connection (the browser build's worker now, the Node host and Electron later).
 */
import type { EngineClient } from "../client/engine-client";
import type { EngineWhere } from "../client/connection-status";
import { EngineContext, useEngine, useEngineState } from "../client/hooks";
import { StimulusOverlay } from "../stimulus/stimulus-view";
import { useConnectionLoss, type LossSource } from "./engine-badge";
import { NoticeLine, ShellFooter, ShellMain } from "./shell-main";
import { ShellToolbar } from "./shell-toolbar";
import { UiContext } from "./ui-context";
import { useEditMode } from "./use-edit-mode";
import { useEventLog } from "./use-event-log";
import { useNotice } from "./use-notice";
import { usePipeline } from "./use-pipeline";
import { useShellPanels } from "./use-shell-panels";
import {
  useBlockActions,
  useDocumentTitle,
  useEditStatic,
  useFirstLoad,
  useLayoutMemory,
  usePipelineLiveValues,
  useReducedMotion,
} from "./use-shell-state";

function Shell({
  initialPipeline,
  sharedEngine,
  engine,
  connection,
}: {
  initialPipeline: string;
  sharedEngine: boolean;
  engine: EngineWhere;
  connection: LossSource | undefined;
}) {
  const client = useEngine();
  // The browser build has no devices at all: it simulates them unless told otherwise.
  const pipeline = usePipeline(client, initialPipeline, !sharedEngine);
  const { graph } = pipeline;
  const state = useEngineState();
  const loss = useConnectionLoss(connection);
  const reducedMotion = useReducedMotion();
  const running = state === "running";
  // The log (per load: its diagnostics, runtime events, replies) and the notices.
  const log = useEventLog(client, pipeline.onLoadReport);
  const { notice, notify } = useNotice(client, log.add);
  const writeLiveValues = usePipelineLiveValues(client, pipeline, notify);
  const panels = useShellPanels(graph, notify, writeLiveValues);
  const { invoke, onGesture } = useBlockActions(client, graph, notify, log.add);
  const editStatic = useEditStatic(client, pipeline, notify);
  const positions = useLayoutMemory(pipeline.file);
  useFirstLoad(client, pipeline, initialPipeline, sharedEngine);
  useDocumentTitle(pipeline);
  const edit = useEditMode(pipeline, notify);
  const stimulusBlock = panels.stimulus !== null ? panels.blocks.get(panels.stimulus) : undefined;

  return (
    <UiContext.Provider value={panels.ui}>
      <div
        className="app"
        data-engine-state={state}
        data-loading={String(pipeline.loading)}
        data-pipeline={pipeline.file ?? ""}
      >
        <ShellToolbar
          pipeline={pipeline}
          state={state}
          edit={edit}
          engine={engine}
          loss={loss}
          notify={notify}
          onStimulus={panels.setStimulus}
        />
        <ShellMain
          pipeline={pipeline}
          running={running}
          loss={loss}
          edit={edit}
          panels={panels}
          editStatic={editStatic}
          positions={positions}
          reducedMotion={reducedMotion}
          invoke={invoke}
          notify={notify}
        />
        <ShellFooter graph={graph} log={log} onGesture={onGesture} />
        <NoticeLine notice={notice} />
        {stimulusBlock ? (
          <StimulusOverlay block={stimulusBlock} onClose={() => panels.setStimulus(null)} />
        ) : null}
      </div>
    </UiContext.Provider>
  );
}

export function App({
  client,
  initialPipeline,
  sharedEngine = false,
  engine = { kind: "page" },
  connection,
}: {
  client: EngineClient;
  initialPipeline: string;
  /** The engine is shared (a Node host or the desktop app): adopt what it already runs. */
  sharedEngine?: boolean;
  /** Where the engine runs (named in the toolbar). */
  engine?: EngineWhere;
  /** The connection to `mosaic serve`, whose refusal or loss the page explains. */
  connection?: LossSource;
}) {
  return (
    <EngineContext.Provider value={client}>
      <Shell
        initialPipeline={initialPipeline}
        sharedEngine={sharedEngine}
        engine={engine}
        connection={connection}
      />
    </EngineContext.Provider>
  );
}
