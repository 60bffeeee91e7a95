/**
 * The app shell: toolbar (pipeline picker, load, start/stop, engine state, timing precision),
 * the BlockTable with the control panels (docked or floating), the gesture keys of simulated EMG,
 * the diagnostics of a pipeline that does not load and the log of runtime events. Works with any
 * engine connection (the browser build's worker now, the Node host and Electron later).
 */
import { useCallback, useEffect, useMemo, useRef, useState } from "react";
import type { EngineState } from "../../engine/protocol";
import type { EngineClient } from "../client/engine-client";
import type { EngineWhere } from "../client/connection-status";
import { EngineContext, useEngine, useEngineInfo, useEngineState } from "../client/hooks";
import { BlockTable } from "../graph/block-table";
import { StimulusOverlay } from "../stimulus/stimulus-view";
import { ParticipantButton } from "../stimulus/participant-button";
import { Editor, EMPTY_FILE } from "../editor/editor";
import { Diagnostics } from "./diagnostics";
import { ConnectionLost, EngineBadge, useConnectionLoss, type LossSource } from "./engine-badge";
import { EventLog } from "./event-log";
import { GestureLegend, useGestureKeys } from "./gestures";
import { setBlockParam } from "../graph/layout-yaml";
import { OpenLocal } from "./open-local";
import { PanelHost, type EditStatic, type OpenPanel } from "./panel-host";
import { PresentationToggle } from "./presentation";
import { RecordControl } from "./record";
import { saveFile } from "./save-file";
import { UiContext, type UiActions } from "./ui-context";
import { usePanelLayouts } from "./use-panel-layouts";
import { usePipeline, type PipelineEntry } from "./use-pipeline";
import { useEventLog } from "./use-event-log";
import { useWriteLiveValues } from "./use-live-values";

const STATE_LABEL: Record<EngineState, string> = {
  empty: "no pipeline",
  loaded: "loaded",
  running: "running",
  stopped: "stopped",
  finished: "finished",
};

function useReducedMotion(): boolean {
  const q = "(prefers-reduced-motion: reduce)";
  const [r, setR] = useState(() => window.matchMedia?.(q).matches ?? false);
  useEffect(() => {
    const m = window.matchMedia?.(q);
    if (!m) return undefined;
    const on = (): void => setR(m.matches);
    m.addEventListener("change", on);
    return () => m.removeEventListener("change", on);
  }, []);
  return r;
}

/** "demo.yaml", "bench/delsys.yaml": the file under pipelines/. */
const shortName = (file: string): string => file.replace(/^pipelines\//, "");

function PipelinePicker({
  index,
  selected,
  onSelect,
}: {
  index: readonly PipelineEntry[];
  selected: string;
  onSelect(file: string): void;
}) {
  const entries = index.some((e) => e.file === selected)
    ? index
    : [{ file: selected, title: selected }, ...index];
  const groups = new Map<string, PipelineEntry[]>();
  for (const e of entries) {
    const dir = shortName(e.file).includes("/") ? shortName(e.file).split("/")[0]! : "";
    groups.set(dir, [...(groups.get(dir) ?? []), e]);
  }
  const title = entries.find((e) => e.file === selected)?.title ?? "";
  return (
    <label className="picker" title={title}>
      <span className="picker__label">Pipeline</span>
      <select
        value={selected}
        onChange={(e) => onSelect(e.target.value)}
        aria-describedby="picker-title"
      >
        {[...groups].map(([dir, es]) =>
          dir === "" ? (
            es.map((e) => (
              <option key={e.file} value={e.file}>
                {shortName(e.file)}
              </option>
            ))
          ) : (
            <optgroup key={dir} label={dir}>
              {es.map((e) => (
                <option key={e.file} value={e.file}>
                  {shortName(e.file)}
                </option>
              ))}
            </optgroup>
          ),
        )}
      </select>
      <span id="picker-title" className="picker__title">
        {title}
      </span>
    </label>
  );
}

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
  const { graph, generation } = pipeline;
  const state = useEngineState();
  const info = useEngineInfo();
  const loss = useConnectionLoss(connection);
  const reducedMotion = useReducedMotion();
  const running = state === "running";

  // ---- log (per load: its diagnostics, runtime events, replies) and notices
  const {
    book: log,
    open: logOpen,
    setOpen: setLogOpen,
    add: addLog,
    clear: clearLog,
  } = useEventLog(client, pipeline.onLoadReport);
  const [notice, setNotice] = useState<{
    text: string;
    level: "info" | "error";
    id: number;
  } | null>(null);
  const nextId = useRef(1);
  const notify = useCallback(
    (message: string, level: "info" | "error" = "info", block = "") => {
      addLog({ t: Date.now() / 1000, level, block, message });
      const text = block && !message.startsWith(block) ? `${block}: ${message}` : message;
      setNotice({ text, level, id: nextId.current++ });
    },
    [addLog],
  );
  // The browser build's engine cannot write files: what it saves comes here to be downloaded.
  useEffect(
    () =>
      client.onDownload((d) => {
        saveFile(d.name, d.mime, d.bytes);
        notify(`downloaded ${d.name}`);
      }),
    [client, notify],
  );
  useEffect(() => {
    if (!notice) return undefined;
    const id = setTimeout(() => setNotice(null), notice.level === "error" ? 8000 : 4000);
    return () => clearTimeout(id);
  }, [notice]);

  // ---- panels
  const [panels, setPanels] = useState<OpenPanel[]>([]);
  const zTop = useRef(10);
  const blocks = useMemo(() => new Map((graph?.blocks ?? []).map((b) => [b.name, b])), [graph]);
  const openSet = useMemo(() => new Set(panels.map((p) => p.name)), [panels]);
  const newPanel = (name: string, count: number): OpenPanel => ({
    name,
    floating: false,
    collapsed: false,
    x: 60 + (count % 6) * 32,
    y: 40 + (count % 6) * 32,
    z: ++zTop.current,
  });
  const [stimulus, setStimulus] = useState<string | null>(null);

  const writeLiveValues = useWriteLiveValues(
    client,
    () =>
      pipeline.file !== undefined && pipeline.source !== undefined
        ? { file: pipeline.file, source: pipeline.source }
        : undefined,
    notify,
  );
  const ui = useMemo<UiActions>(
    () => ({
      togglePanel: (name) =>
        setPanels((ps) =>
          ps.some((p) => p.name === name)
            ? ps.filter((p) => p.name !== name)
            : [...ps, newPanel(name, ps.length)],
        ),
      openPanel: (name) =>
        setPanels((ps) =>
          ps.some((p) => p.name === name)
            ? ps.map((p) => (p.name === name ? { ...p, collapsed: false, z: ++zTop.current } : p))
            : [...ps, newPanel(name, ps.length)],
        ),
      closePanel: (name) => setPanels((ps) => ps.filter((p) => p.name !== name)),
      openStimulus: (name) => setStimulus(name),
      notify,
      writeLiveValues,
    }),
    [notify, writeLiveValues],
  );

  // A new load keeps the panels of blocks that are still there (same name and type).
  const lastGraph = useRef(graph);
  useEffect(() => {
    const prev = lastGraph.current;
    lastGraph.current = graph;
    if (prev === graph) return;
    setPanels((ps) =>
      ps.filter((p) => {
        const before = prev?.blocks.find((b) => b.name === p.name);
        const now = graph?.blocks.find((b) => b.name === p.name);
        return now !== undefined && before?.type === now.type;
      }),
    );
    setStimulus((s) => (s !== null && graph?.blocks.some((b) => b.name === s) ? s : null));
  }, [graph]);
  // Another pipeline (or the page) loaded: the panels saved for it come back (localStorage).
  const nextZ = useCallback(() => ++zTop.current, []);
  usePanelLayouts(graph, panels, setPanels, nextZ);

  // ---- actions
  const invoke = useCallback(
    (block: string, action: string, arg: unknown, label: string) => {
      void client.invoke(block, action, arg).then((r) => {
        notify(
          r.message ?? (r.ok ? `${label}: done` : `${label}: failed`),
          r.ok ? "info" : "error",
          block,
        );
      });
    },
    [client, notify],
  );
  const onGesture = useCallback(
    (message: string, ok: boolean, block: string) => {
      if (!ok) notify(message, "error", block);
      else addLog({ t: Date.now() / 1000, level: "info", block, message });
    },
    [notify, addLog],
  );
  useGestureKeys(client, graph, onGesture);

  // A param that is not live, changed while stopped: edit the file's text and load it again
  // (the old text comes back when the new one does not load). "Save layout…" downloads it.
  const current = useRef(pipeline);
  current.current = pipeline;
  const editStatic = useCallback<EditStatic>(
    async (block, param, value) => {
      const { file, source } = current.current;
      if (file === undefined || source === undefined)
        return { ok: false, message: "no pipeline file" };
      if (client.state === "running") return { ok: false, message: "stop the pipeline first" };
      let text: string;
      try {
        text = setBlockParam(source, block, param, value);
      } catch (e) {
        return { ok: false, message: (e as Error).message };
      }
      const r = await current.current.loadSource(file, text, false, true);
      if (r.ok) {
        notify(
          `${param} = ${JSON.stringify(value)}: pipeline reloaded (Start to run it)`,
          "info",
          block,
        );
        return { ok: true, message: "reloaded with the new value" };
      }
      const why =
        r.diagnostics?.find((d) => d.severity === "error")?.message ?? r.message ?? "failed";
      await current.current.loadSource(file, source, false, true);
      return { ok: false, message: why };
    },
    [client, notify],
  );

  // Node positions survive reloading the same file (a param edit, Load again).
  const layoutMemory = useRef<{
    file: string | undefined;
    positions: Map<string, { x: number; y: number }>;
  }>({
    file: undefined,
    positions: new Map(),
  });
  if (layoutMemory.current.file !== pipeline.file) {
    layoutMemory.current = { file: pipeline.file, positions: new Map() };
  }

  // ---- first load
  const started = useRef(false);
  useEffect(() => {
    if (started.current) return;
    started.current = true;
    if (!sharedEngine) {
      void pipeline.load(initialPipeline);
      return;
    }
    // A shared engine (mosaic serve, the desktop app) may already run a pipeline: its first
    // state message (after hello and the graph, if any) tells. Show that one; else load ours.
    const off = client.onState((st) => {
      off();
      if (st !== "empty" && client.graph) pipeline.adopt(client.graph);
      else void pipeline.load(initialPipeline);
    });
  }, [pipeline, initialPipeline, sharedEngine, client]);

  // The window's title names what the engine has (the header's picker does too).
  useEffect(() => {
    const name = pipeline.file !== undefined && graph !== undefined ? shortName(pipeline.file) : "";
    document.title = name ? `${name} — MOSAIC` : "MOSAIC — live pipeline";
  }, [pipeline.file, graph]);

  const selectPipeline = (file: string): void => {
    pipeline.select(file);
    const url = new URL(window.location.href);
    url.searchParams.set("pipeline", file);
    window.history.replaceState(null, "", url);
  };

  const start = (): void => {
    if (state === "finished" && pipeline.file !== undefined && pipeline.source !== undefined) {
      void pipeline.loadSource(pipeline.file, pipeline.source, true, true);
    } else void client.start();
  };

  const failed = graph === undefined && !pipeline.loading && pipeline.file !== undefined;
  const stimuli = graph?.blocks.filter((b) => b.type === "Stimulus") ?? [];
  const stimulusBlock = stimulus !== null ? blocks.get(stimulus) : undefined;
  const [warningsHidden, setWarningsHidden] = useState(-1);

  // ---- edit mode (issue 8): the editor holds its own text; Apply loads it and starts it.
  const [editing, setEditing] = useState(false);
  const [applying, setApplying] = useState(false);
  const draft = useRef<{ file: string; text: string } | null>(null);
  const onDraft = useCallback((file: string, text: string) => {
    draft.current = { file, text };
  }, []);
  const applyEdit = useCallback(async (file: string, text: string) => {
    setApplying(true);
    try {
      return await current.current.loadSource(file, text, true);
    } finally {
      setApplying(false);
    }
  }, []);
  const editFile = draft.current?.file ?? pipeline.file ?? EMPTY_FILE;
  const editText =
    draft.current?.text ?? (pipeline.file !== undefined ? (pipeline.source ?? "") : "");
  // A draft is kept while leaving edit mode (said so), and dropped when another load happens.
  useEffect(() => {
    if (!editingRef.current) draft.current = null;
  }, [generation]);
  const editingRef = useRef(editing);
  editingRef.current = editing;
  const leaveEdit = (): void => {
    setEditing(false);
    const d = draft.current;
    if (d && (d.text !== (pipeline.source ?? "") || d.file !== pipeline.file))
      notify("Edits not applied are kept: press Edit to go on with them");
    else draft.current = null;
  };
  const editorNotify = useCallback(
    (m: string, level?: "info" | "error") => notify(m, level),
    [notify],
  );

  return (
    <UiContext.Provider value={ui}>
      <div
        className="app"
        data-engine-state={state}
        data-loading={String(pipeline.loading)}
        data-pipeline={pipeline.file ?? ""}
      >
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
            disabled={graph === undefined || running || pipeline.loading}
          >
            Start
          </button>
          <button type="button" onClick={() => void client.stop()} disabled={!running}>
            Stop
          </button>
          <RecordControl graph={graph} running={running} notify={notify} />
          <span
            className={`engine-state state-${state}`}
            role="status"
            aria-label={`Engine ${STATE_LABEL[state]}`}
          >
            <span className="engine-state__dot" aria-hidden="true" />
            {applying ? "restarting…" : pipeline.loading ? "loading…" : STATE_LABEL[state]}
          </span>
          {stimuli.length > 0 ? (
            <button
              type="button"
              onClick={() => setStimulus(stimuli[0]!.name)}
              title="Show the participant's cues full screen"
            >
              Stimulus
            </button>
          ) : null}
          {stimuli.length > 0 ? <ParticipantButton block={stimuli[0]!.name} /> : null}
          <button
            type="button"
            aria-pressed={editing}
            onClick={() => (editing ? leaveEdit() : setEditing(true))}
            disabled={pipeline.loading && !editing}
            title="Edit the pipeline: palette, canvas, inspector and YAML side by side"
          >
            Edit
          </button>
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
          <PresentationToggle />
          <span className="toolbar__spacer" />
          <EngineBadge where={engine} />
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
        </header>

        <main className="main">
          {loss ? <ConnectionLost loss={loss} /> : null}
          {editing ? (
            <Editor
              client={client}
              initialText={editText}
              initialFile={editFile}
              appliedText={pipeline.source}
              templates={pipeline.index}
              graph={graph}
              running={running}
              applying={applying}
              onApply={applyEdit}
              onNotify={editorNotify}
              onDraft={onDraft}
              onClose={leaveEdit}
            />
          ) : null}
          {!editing && graph !== undefined && pipeline.rejected ? (
            <div className="warnings-banner rejected-banner" data-rejected={pipeline.rejected.file}>
              <p>
                <strong>{shortName(pipeline.rejected.file)}</strong> was not loaded:{" "}
                <strong>{shortName(pipeline.file ?? "")}</strong> goes on{" "}
                {running ? "running" : "loaded"}.
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
          ) : null}
          {!editing &&
          graph !== undefined &&
          pipeline.diagnostics.length > 0 &&
          warningsHidden !== generation ? (
            <div className="warnings-banner">
              <Diagnostics diagnostics={pipeline.diagnostics} error={undefined} failed={false} />
              <button
                type="button"
                aria-label="Dismiss the warnings"
                onClick={() => setWarningsHidden(generation)}
              >
                ×
              </button>
            </div>
          ) : null}
          {editing ? null : graph !== undefined ? (
            <PanelHost
              panels={panels}
              blocks={blocks}
              onEditStatic={editStatic}
              onClose={ui.closePanel}
              onUpdate={(name, u) =>
                setPanels((ps) =>
                  ps.map((p) =>
                    p.name === name
                      ? {
                          ...p,
                          ...u,
                          ...(u.floating === true && !p.floating ? { z: ++zTop.current } : {}),
                        }
                      : p,
                  ),
                )
              }
              onRaise={(name) =>
                setPanels((ps) => {
                  const p = ps.find((x) => x.name === name);
                  if (!p || !p.floating || p.z === zTop.current) return ps;
                  const z = ++zTop.current;
                  return ps.map((x) => (x.name === name ? { ...x, z } : x));
                })
              }
            >
              <BlockTable
                key={generation}
                graph={graph}
                source={pipeline.source}
                positions={layoutMemory.current.positions}
                running={running}
                openPanels={openSet}
                reducedMotion={reducedMotion}
                onTogglePanel={ui.togglePanel}
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
          )}
        </main>

        <footer className="footer">
          <GestureLegend graph={graph} onResult={onGesture} />
          <EventLog
            book={log}
            open={logOpen}
            onToggle={() => setLogOpen((o) => !o)}
            onClear={clearLog}
          />
        </footer>

        <div
          className={`notice${notice ? ` is-shown level-${notice.level}` : ""}`}
          role="status"
          aria-live="polite"
        >
          {notice?.text ?? ""}
        </div>
        {stimulusBlock ? (
          <StimulusOverlay block={stimulusBlock} onClose={() => setStimulus(null)} />
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
