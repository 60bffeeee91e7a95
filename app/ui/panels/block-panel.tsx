/**
 * A block's control panel (paper III-C): one tab per view the block declares (`BlockInfo.views`:
 * scope, spider, heatmap, label), its params as a live form, and its status history. The
 * "stimulus" view belongs to the participant-facing Stimulus view: a button asks the host to open
 * it. Engine data flows only while `visible` and only for the open tab; a hidden or closed panel
 * unwatches its outputs and leaves no animation frame or observer behind. Telemetry (sent anyway)
 * is recorded for the Status tab as long as the panel exists.
 */
import {
  useCallback,
  useEffect,
  useId,
  useMemo,
  useState,
  type KeyboardEvent,
  type ReactNode,
} from "react";
import type { BlockInfo } from "../../engine/protocol";
import { useUi } from "../app/ui-context";
import { useEngine, useEngineState, useLiveBlock } from "../client/hooks";
import { restoreSettings, type PanelView } from "../app/panel-layouts";
import { useReportView } from "../app/use-panel-layouts";
import { ParamsForm, type SetResult } from "../forms/params-form";
import { HEATMAP_DEFAULTS, Heatmap, type HeatmapSettings } from "./heatmap";
import { LabelDisplay } from "./labels";
import { PlayerView } from "./player-view";
import { SCOPE_DEFAULTS, Scope, type ScopeSettings } from "./scope";
import { SPIDER_DEFAULTS, SpiderPlot, type SpiderSettings } from "./spider";
import { StatusView, useStatusRecorder } from "./status";
import { TrainingView } from "./training-view";
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

type DataView = "scope" | "spider" | "heatmap" | "label" | "training" | "player";
type Tab = DataView | "params" | "status";

const TAB_TITLE: Record<Tab, string> = {
  scope: "Scope",
  spider: "Spider",
  heatmap: "Heatmap",
  label: "Labels",
  training: "Training",
  player: "Player",
  params: "Params",
  status: "Status",
};
const DATA_VIEWS: readonly string[] = ["scope", "spider", "heatmap", "label", "training", "player"];

interface Settings {
  scope: ScopeSettings;
  spider: SpiderSettings;
  heatmap: HeatmapSettings;
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
  const tabs = useMemo<Tab[]>(
    () => [
      ...(block.views.filter((v) => DATA_VIEWS.includes(v)) as DataView[]),
      "params",
      "status",
    ],
    [block.views],
  );
  const [chosen, setTab] = useState<Tab>(() => (view?.tab as Tab | undefined) ?? tabs[0]!);
  const tab = tabs.includes(chosen) ? chosen : tabs[0]!;
  // Outputs with values (timers' ticks carry none).
  const outputs = block.outputs as OutputInfo[];
  const valued = outputs.filter((o) => o.shape.rows * o.shape.cols > 0);
  const [portName, setPort] = useState<string | undefined>(view?.port ?? valued[0]?.name);
  const output = valued.find((o) => o.name === portName) ?? valued[0];
  const [settings, setSettings] = useState<Settings>(() => ({
    scope: restoreSettings(SCOPE_DEFAULTS, view?.settings?.scope),
    spider: restoreSettings(SPIDER_DEFAULTS, view?.settings?.spider),
    heatmap: restoreSettings(HEATMAP_DEFAULTS, view?.settings?.heatmap),
  }));
  useReportView(onView, tab, output?.name, settings);
  const patch = useCallback(
    <K extends keyof Settings>(k: K) =>
      (p: Partial<Settings[K]>) =>
        setSettings((s) => ({ ...s, [k]: { ...s[k], ...p } })),
    [],
  );
  const onSet = useCallback(
    (param: string, value: unknown) => client.setParam(block.name, param, value),
    [client, block.name],
  );
  const hasStimulus = block.views.includes("stimulus");
  const base = useId();
  const onTabKey = (e: KeyboardEvent<HTMLDivElement>): void => {
    const i = tabs.indexOf(tab);
    const next =
      e.key === "ArrowRight"
        ? i + 1
        : e.key === "ArrowLeft"
          ? i - 1
          : e.key === "Home"
            ? 0
            : e.key === "End"
              ? tabs.length - 1
              : -2;
    if (next === -2) return;
    e.preventDefault();
    const t = tabs[(next + tabs.length) % tabs.length]!;
    setTab(t);
    document.getElementById(`${base}-tab-${t}`)?.focus();
  };
  const onKey = (e: KeyboardEvent<HTMLElement>): void => {
    const el = e.target as HTMLElement;
    if (e.key === "Escape" && onClose && !el.closest("input, select, textarea, [role=tablist]"))
      onClose();
  };

  const isData = DATA_VIEWS.includes(tab);
  const tools =
    valued.length > 1 && output ? (
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
    ) : undefined;
  const active = visible && isData;
  let body: ReactNode;
  if (tab === "params") {
    body = <LiveParamsForm block={block} onSet={onSet} onEditStatic={onEditStatic} />;
  } else if (tab === "status") {
    body = <StatusView block={block} recorder={recorder} active={visible} />;
  } else if (tab === "label") {
    body = <LabelDisplay block={block} active={active} />;
  } else if (tab === "training") {
    body = <TrainingView block={block} active={active} />;
  } else if (tab === "player") {
    body = <PlayerView block={block} active={active} />;
  } else if (!output) {
    body = <p className="mp-muted">{block.name} has no output with values to show.</p>;
  } else if (tab === "scope") {
    body = (
      <Scope
        key={output.name}
        tools={tools}
        block={block}
        output={output}
        active={active}
        settings={settings.scope}
        onSettings={patch("scope")}
      />
    );
  } else if (tab === "spider") {
    body = (
      <SpiderPlot
        key={output.name}
        tools={tools}
        block={block}
        output={output}
        active={active}
        settings={settings.spider}
        onSettings={patch("spider")}
      />
    );
  } else {
    body = (
      <Heatmap
        key={output.name}
        tools={tools}
        block={block}
        output={output}
        active={active}
        settings={settings.heatmap}
        onSettings={patch("heatmap")}
      />
    );
  }

  return (
    <div
      className="mp-panel"
      data-block-panel={block.name}
      data-visible={String(visible)}
      onKeyDown={onKey}
    >
      <p className="mp-summary">{block.summary}</p>
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
      <div
        id={`${base}-panel`}
        role="tabpanel"
        aria-labelledby={`${base}-tab-${tab}`}
        className="mp-tabpanel"
      >
        {body}
      </div>
      <Actions block={block} loaded={engineState !== "empty"} />
    </div>
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
