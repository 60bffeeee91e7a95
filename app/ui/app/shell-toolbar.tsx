/**
 * The app shell's toolbar: pipeline picker, Load and Open, Start and Stop, recording, the
 * engine's state, the Stimulus views, Edit, simulated devices, presentation mode, which engine
 * runs and how precise its timing is.
 */
import type { EngineState } from "../../engine/protocol";
import type { ConnectionLoss, EngineWhere } from "../client/connection-status";
import { useEngine, useEngineInfo } from "../client/hooks";
import { ParticipantButton } from "../stimulus/participant-button";
import { EngineBadge } from "./engine-badge";
import { OpenLocal } from "./open-local";
import { PipelinePicker } from "./pipeline-picker";
import { PresentationToggle } from "./presentation";
import { RecordControl } from "./record";
import type { EditMode } from "./use-edit-mode";
import type { Notify } from "./use-notice";
import { usePipelineControls, type Pipeline } from "./use-shell-state";

const STATE_LABEL: Record<EngineState, string> = {
  empty: "no pipeline",
  loaded: "loaded",
  running: "running",
  stopped: "stopped",
  finished: "finished",
};

function EngineStateLabel({
  state,
  applying,
  loading,
}: {
  state: EngineState;
  applying: boolean;
  loading: boolean;
}) {
  return (
    <span
      className={`engine-state state-${state}`}
      role="status"
      aria-label={`Engine ${STATE_LABEL[state]}`}
    >
      <span className="engine-state__dot" aria-hidden="true" />
      {applying ? "restarting…" : loading ? "loading…" : STATE_LABEL[state]}
    </span>
  );
}

/** The participant's cues full screen, and in a window of their own (the first Stimulus block). */
function StimulusButtons({
  pipeline,
  onStimulus,
}: {
  pipeline: Pipeline;
  onStimulus(name: string): void;
}) {
  const stimuli = pipeline.graph?.blocks.filter((b) => b.type === "Stimulus") ?? [];
  return (
    <>
      {stimuli.length > 0 ? (
        <button
          type="button"
          onClick={() => onStimulus(stimuli[0]!.name)}
          title="Show the participant's cues full screen"
        >
          Stimulus
        </button>
      ) : null}
      {stimuli.length > 0 ? <ParticipantButton block={stimuli[0]!.name} /> : null}
    </>
  );
}

/** Simulators in place of devices; changing it loads the pipeline again. */
function SimulateDevices({ pipeline, running }: { pipeline: Pipeline; running: boolean }) {
  return (
    <label
      className="toggle simulate-devices"
      title={
        "Replace device blocks (Myo, Muovi, Delsys, NilsPod, …) by simulators of the same " +
        "shape and rate, and output devices (BlenderArm, Hannes, UDP, ROS) by blocks that " +
        "count what they would have sent, so any pipeline runs without hardware. " +
        "Changing it loads the pipeline again."
      }
    >
      <input
        type="checkbox"
        checked={pipeline.simulateDevices}
        disabled={pipeline.loading}
        onChange={(e) => {
          const on = e.target.checked;
          pipeline.setSimulateDevices(on);
          if (pipeline.file !== undefined && pipeline.source !== undefined) {
            void pipeline.loadSource(pipeline.file, pipeline.source, running, true);
          }
        }}
      />
      Simulate devices
    </label>
  );
}

function Timing({ loss }: { loss: ConnectionLoss | undefined }) {
  const info = useEngineInfo();
  return (
    <span
      className={`timing ${info.sharedMemory ? "is-precise" : "is-coarse"}`}
      data-shared-memory={String(info.sharedMemory)}
      title={info.engine}
    >
      {!info.connected
        ? loss
          ? "not connected"
          : "engine starting…"
        : info.sharedMemory
          ? "precise timing (shared memory)"
          : "coarse timing (no shared memory)"}
    </span>
  );
}

export function ShellToolbar({
  pipeline,
  state,
  edit,
  engine,
  loss,
  notify,
  onStimulus,
}: {
  pipeline: Pipeline;
  state: EngineState;
  edit: EditMode;
  engine: EngineWhere;
  loss: ConnectionLoss | undefined;
  notify: Notify;
  onStimulus(name: string): void;
}) {
  const client = useEngine();
  const { selectPipeline, start } = usePipelineControls(client, pipeline, state);
  const running = state === "running";
  return (
    <header className="toolbar">
      <div className="toolbar__brand" aria-label="MOSAIC">
        MOSAIC
      </div>
      <PipelinePicker
        index={pipeline.index}
        selected={pipeline.selected}
        onSelect={selectPipeline}
      />
      <button
        type="button"
        onClick={() => void pipeline.load(pipeline.selected)}
        disabled={pipeline.loading}
        title="Load the selected pipeline and start it"
      >
        Load
      </button>
      <OpenLocal
        inPage={engine.kind === "page"}
        onOpen={(file, text) => pipeline.loadSource(file, text)}
        notify={notify}
      />
      <span className="toolbar__sep" aria-hidden="true" />
      <button
        type="button"
        className="primary"
        onClick={start}
        disabled={pipeline.graph === undefined || running || pipeline.loading}
      >
        Start
      </button>
      <button type="button" onClick={() => void client.stop()} disabled={!running}>
        Stop
      </button>
      <RecordControl graph={pipeline.graph} running={running} notify={notify} />
      <EngineStateLabel state={state} applying={edit.applying} loading={pipeline.loading} />
      <StimulusButtons pipeline={pipeline} onStimulus={onStimulus} />
      <button
        type="button"
        aria-pressed={edit.editing}
        onClick={edit.toggle}
        disabled={pipeline.loading && !edit.editing}
        title="Edit the pipeline: palette, canvas, inspector and YAML side by side"
      >
        Edit
      </button>
      <SimulateDevices pipeline={pipeline} running={running} />
      <PresentationToggle />
      <span className="toolbar__spacer" />
      <EngineBadge where={engine} />
      <Timing loss={loss} />
    </header>
  );
}
