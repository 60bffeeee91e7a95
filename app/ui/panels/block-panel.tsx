/**
 * A block's control panel (paper III-C): one tab per view the block declares (`BlockInfo.views`:
 * scope, spider, heatmap, label), its params as a live form, and its status history. The
 * "stimulus" view belongs to the participant-facing Stimulus view: a button asks the host to open
 * it. Engine data flows only while `visible` and only for the open tab; a hidden or closed panel
 * unwatches its outputs and leaves no animation frame or observer behind. Telemetry (sent anyway)
 * is recorded for the Status tab as long as the panel exists.
 */
import { useCallback, useEffect, useState, type KeyboardEvent, type ReactNode } from "react";
import type { BlockInfo } from "../../engine/protocol";
import { useUi } from "../app/ui-context";
import { useEngine, useEngineState, useLiveBlock } from "../client/hooks";
import type { PanelView } from "../app/panel-layouts";
import { useReportView } from "../app/use-panel-layouts";
import { ParamsForm, type SetResult } from "../forms/params-form";
import { Heatmap } from "./heatmap";
import { LabelDisplay } from "./labels";
import { PlayerView } from "./player-view";
import { Scope } from "./scope";
import { SpiderPlot } from "./spider";
import { StatusView, useStatusRecorder, type StatusRecorder } from "./status";
import { TrainingView } from "./training-view";
import { DATA_VIEWS, TAB_TITLE, usePanelTabs, type PanelTabs, type Tab } from "./use-panel-tabs";
import {
  usePanelOutput,
  useViewSettings,
  type PanelOutput,
  type PatchSettings,
  type ViewSettings,
} from "./use-panel-view";
import type { OutputInfo } from "./view-props";
import "./panels.css";

export interface BlockPanelProps {
  block: BlockInfo;
  /** Shown on screen: data is watched and plots drawn only while true. */
  visible: boolean;
  onClose?: () => void;
  /** Opens the participant-facing Stimulus view of this block (blocks with a "stimulus" view). */
  onOpenStimulus?: () => void;
  /** Changes a non-live param while the pipeline is not running (the host reloads the file). */
  onEditStatic?: (param: string, value: unknown) => Promise<SetResult>;
  /** A saved view to open with (saved panel layouts, app/ui/app/panel-layouts.ts). */
  view?: PanelView;
  /** Told the view (tab, output, view settings) whenever it changes. */
  onView?: (view: PanelView) => void;
}

export function BlockPanel({
  block,
  visible,
  onClose,
  onOpenStimulus,
  onEditStatic,
  view,
  onView,
}: BlockPanelProps): ReactNode {
  const client = useEngine();
  const engineState = useEngineState();
  const recorder = useStatusRecorder(block.name);
  const tabs = usePanelTabs(block.views, view?.tab);
  const out = usePanelOutput(block, view);
  const { settings, patch } = useViewSettings(view);
  useReportView(onView, tabs.tab, out.output?.name, settings);
  const onSet = useCallback(
    (param: string, value: unknown) => client.setParam(block.name, param, value),
    [client, block.name],
  );
  const onKey = (e: KeyboardEvent<HTMLElement>): void => {
    const el = e.target as HTMLElement;
    if (e.key === "Escape" && onClose && !el.closest("input, select, textarea, [role=tablist]"))
      onClose();
  };
  const { base, tab } = tabs;

  return (
    <div
      className="mp-panel"
      data-block-panel={block.name}
      data-visible={String(visible)}
      onKeyDown={onKey}
    >
      <p className="mp-summary">{block.summary}</p>
      <PanelTabBar block={block} tabs={tabs} onOpenStimulus={onOpenStimulus} />
      <div
        id={`${base}-panel`}
        role="tabpanel"
        aria-labelledby={`${base}-tab-${tab}`}
        className="mp-tabpanel"
      >
        <PanelBody
          block={block}
          tab={tab}
          visible={visible}
          out={out}
          settings={settings}
          patch={patch}
          recorder={recorder}
          onSet={onSet}
          onEditStatic={onEditStatic}
        />
      </div>
      <Actions block={block} loaded={engineState !== "empty"} />
    </div>
  );
}

/** The tabs and, for a block with a "stimulus" view, the button that opens it. */
function PanelTabBar({
  block,
  tabs: { tabs, tab, setTab, base, onTabKey },
  onOpenStimulus,
}: {
  block: BlockInfo;
  tabs: PanelTabs;
  onOpenStimulus: (() => void) | undefined;
}): ReactNode {
  const hasStimulus = block.views.includes("stimulus");
  return (
    <div className="mp-tabbar">
      <div
        className="mp-tabs"
        role="tablist"
        aria-label={`${block.name} views`}
        onKeyDown={onTabKey}
      >
        {tabs.map((t) => (
          <button
            key={t}
            id={`${base}-tab-${t}`}
            type="button"
            role="tab"
            className="mp-tab"
            aria-selected={t === tab}
            aria-controls={`${base}-panel`}
            tabIndex={t === tab ? 0 : -1}
            data-tab={t}
            onClick={() => setTab(t)}
          >
            {TAB_TITLE[t]}
          </button>
        ))}
      </div>
      {hasStimulus && (
        <button
          type="button"
          className="mp-btn mp-stimulus-btn"
          onClick={onOpenStimulus}
          disabled={!onOpenStimulus}
          title="Open the participant-facing Stimulus view"
        >
          Stimulus view ↗
        </button>
      )}
    </div>
  );
}

/** The output picker shown in a plot's toolbar when the block has several outputs with values. */
function OutputPicker({
  valued,
  output,
  setPort,
}: {
  valued: readonly OutputInfo[];
  output: OutputInfo;
  setPort: (name: string) => void;
}): ReactNode {
  return (
    <label className="mp-field mp-port">
      Output
      <select value={output.name} onChange={(e) => setPort(e.target.value)}>
        {valued.map((o) => (
          <option key={o.name} value={o.name}>
            {o.name} [{o.shape.rows}, {o.shape.cols}]
          </option>
        ))}
      </select>
    </label>
  );
}

interface PanelBodyProps {
  block: BlockInfo;
  tab: Tab;
  visible: boolean;
  out: PanelOutput;
  settings: ViewSettings;
  patch: PatchSettings;
  recorder: StatusRecorder;
  onSet: (param: string, value: unknown) => Promise<SetResult>;
  onEditStatic: ((param: string, value: unknown) => Promise<SetResult>) | undefined;
}

/** The open tab's content; a data view gets data only while the panel is visible. */
function PanelBody(props: PanelBodyProps): ReactNode {
  const { block, tab, visible, settings, patch } = props;
  const { valued, output, setPort } = props.out;
  const active = visible && DATA_VIEWS.includes(tab);
  if (tab === "params")
    return <LiveParamsForm block={block} onSet={props.onSet} onEditStatic={props.onEditStatic} />;
  if (tab === "status")
    return <StatusView block={block} recorder={props.recorder} active={visible} />;
  if (tab === "label") return <LabelDisplay block={block} active={active} />;
  if (tab === "training") return <TrainingView block={block} active={active} />;
  if (tab === "player") return <PlayerView block={block} active={active} />;
  if (!output) return <p className="mp-muted">{block.name} has no output with values to show.</p>;
  const tools =
    valued.length > 1 ? (
      <OutputPicker valued={valued} output={output} setPort={setPort} />
    ) : undefined;
  const common = { tools, block, output, active };
  if (tab === "scope")
    return (
      <Scope key={output.name} {...common} settings={settings.scope} onSettings={patch("scope")} />
    );
  if (tab === "spider")
    return (
      <SpiderPlot
        key={output.name}
        {...common}
        settings={settings.spider}
        onSettings={patch("spider")}
      />
    );
  return (
    <Heatmap
      key={output.name}
      {...common}
      settings={settings.heatmap}
      onSettings={patch("heatmap")}
    />
  );
}

/** The block's actions (its own and the built-in reset), with an optional argument. */
function Actions({ block, loaded }: { block: BlockInfo; loaded: boolean }): ReactNode {
  const client = useEngine();
  const actions = block.actions.filter((a) => a.name !== "subscribe" && a.name !== "unsubscribe");
  const [name, setName] = useState(actions[0]?.name ?? "");
  const [arg, setArg] = useState("");
  const [reply, setReply] = useState<{ ok: boolean; message: string } | null>(null);
  useEffect(() => setReply(null), [name]);
  if (actions.length === 0) return null;
  const action = actions.find((a) => a.name === name) ?? actions[0]!;
  const run = async (): Promise<void> => {
    let value: unknown = undefined;
    const s = arg.trim();
    if (s !== "") {
      try {
        value = JSON.parse(s);
      } catch {
        value = s;
      }
    }
    setReply(null);
    const r = await client.invoke(block.name, action.name, value);
    setReply({ ok: r.ok, message: r.message ?? (r.ok ? "done" : "failed") });
  };
  return (
    <details className="mp-actions">
      <summary>Actions</summary>
      <div className="mp-toolbar">
        <label className="mp-field">
          Action
          <select value={action.name} onChange={(e) => setName(e.target.value)}>
            {actions.map((a) => (
              <option key={a.name} value={a.name}>
                {a.label}
              </option>
            ))}
          </select>
        </label>
        <label className="mp-field">
          Argument
          <input
            value={arg}
            onChange={(e) => setArg(e.target.value)}
            placeholder="optional"
            onKeyDown={(e) => e.key === "Enter" && void run()}
          />
        </label>
        <button type="button" className="mp-btn" disabled={!loaded} onClick={() => void run()}>
          Run
        </button>
      </div>
      {action.description && <p className="mp-muted">{action.description}</p>}
      {reply && (
        <p className={reply.ok ? "mp-ok" : "mp-error"} role={reply.ok ? undefined : "alert"}>
          {reply.message}
        </p>
      )}
    </details>
  );
}

/** The params form with the engine's current values (any client's changes) and the file's. */
function LiveParamsForm({
  block,
  onSet,
  onEditStatic,
}: {
  block: BlockInfo;
  onSet: (param: string, value: unknown) => Promise<SetResult>;
  onEditStatic: ((param: string, value: unknown) => Promise<SetResult>) | undefined;
}): ReactNode {
  const live = useLiveBlock(block);
  const engineState = useEngineState();
  const { writeLiveValues } = useUi();
  return (
    <ParamsForm
      block={live}
      engineState={engineState}
      onSet={onSet}
      {...(onEditStatic ? { onEditStatic } : {})}
      {...(writeLiveValues ? { onWriteBack: writeLiveValues } : {})}
    />
  );
}
