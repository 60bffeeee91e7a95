/**
 * The participant's view of a Stimulus block (paper III-G): the current cue in large type, what
 * to do now (relax, get ready, hold, release), a progress bar of the phase and the time left; the
 * target ramp as an effort gauge. Built from the block's `cue`, `phase` and `target` outputs
 * (watched while visible) and its status text. `StimulusOverlay` shows it full screen.
 */
import { useEffect, useMemo, useRef } from "react";
import type { BlockInfo } from "../../engine/protocol";
import { useEngine, useTelemetrySelector } from "../client/hooks";
import { PHASES, cueLabels, type Phase } from "./cues";
import { stimulusState } from "./stimulus-state";
import { useCountdownTick, useStimulusLive } from "./use-stimulus-live";

/** What the participant is asked to do in a phase. */
export function instruction(phase: Phase | undefined, label: string): string {
  switch (phase) {
    case "rest":
      return "Relax";
    case "rise":
      return `Get ready: ${label}`;
    case "hold":
      return `Hold ${label}`;
    case "capture":
      return `Hold ${label} — recording`;
    case "fall":
      return "Release";
    case "end":
      return "Done — thank you";
    default:
      return "Waiting";
  }
}

export function StimulusView({
  block,
  visible,
  large = false,
  onFullscreen,
}: {
  block: BlockInfo;
  visible: boolean;
  /** Full-screen size (the participant's screen). */
  large?: boolean;
  onFullscreen?: () => void;
}) {
  const client = useEngine();
  const labels = useMemo(() => cueLabels(block.params), [block.params]);
  const live = useStimulusLive(block.name, visible);
  const text = useTelemetrySelector(
    (t) => t?.blocks.find((b) => b.name === block.name)?.text ?? "",
    Object.is,
  );
  // The countdown moves between data messages: a render at 10 Hz while a phase runs (reduced
  // motion stops only the CSS transitions, styles.css).
  useCountdownTick(visible, live.phase);
  const { running, phase, label, left, progress, count } = stimulusState(
    live,
    text,
    labels,
    block.params,
  );
  const invoke = (action: string): void => {
    void client.invoke(block.name, action);
  };

  return (
    <div
      className={`stimulus${large ? " stimulus--large" : ""} stimulus--${phase ?? "waiting"}`}
      data-stimulus={block.name}
      data-phase={phase ?? "none"}
    >
      <div className="stimulus__cue" aria-live="polite" data-cue={label}>
        {running && phase !== "rest" ? label : phase === "rest" ? "Rest" : ""}
        {!running ? (
          <span className="stimulus__idle">{text || "Waiting for the protocol"}</span>
        ) : null}
      </div>
      <div className="stimulus__instruction">{running ? instruction(phase, label) : ""}</div>
      <PhaseRow phase={phase} count={count} />
      <PhaseProgress phase={phase} progress={progress} />
      <div className="stimulus__footer">
        <span className="stimulus__left" data-left={Number.isFinite(left) ? left.toFixed(1) : ""}>
          {Number.isFinite(left) ? `${left.toFixed(1)} s left` : " "}
        </span>
        <EffortGauge effort={live.effort} running={running} />
      </div>
      <ProtocolControls invoke={invoke} onFullscreen={onFullscreen} />
    </div>
  );
}

/** The protocol's phases, the current one marked, and the cue count ("2 of 10"). */
function PhaseRow({ phase, count }: { phase: Phase | undefined; count: string }) {
  return (
    <div className="stimulus__phase-row">
      <ol className="stimulus__phases" aria-label="Phases">
        {PHASES.slice(0, 5).map((ph) => (
          <li
            key={ph}
            className={ph === phase ? "is-current" : undefined}
            aria-current={ph === phase ? "step" : undefined}
          >
            {ph}
          </li>
        ))}
      </ol>
      <span className="stimulus__count">{count}</span>
    </div>
  );
}

/** The phase's progress bar. */
function PhaseProgress({ phase, progress }: { phase: Phase | undefined; progress: number }) {
  return (
    <div
      className="stimulus__progress"
      role="progressbar"
      aria-label={`${phase ?? "phase"} progress`}
      aria-valuemin={0}
      aria-valuemax={100}
      aria-valuenow={Math.round(progress * 100)}
    >
      <div className="stimulus__bar" style={{ transform: `scaleX(${progress})` }} />
    </div>
  );
}

/** The target ramp as an effort gauge (empty while the protocol does not run). */
function EffortGauge({ effort, running }: { effort: number; running: boolean }) {
  return (
    <div className="stimulus__effort" aria-label={`target ${Math.round(effort * 100)} %`}>
      <span>target</span>
      <div className="stimulus__gauge">
        <div style={{ transform: `scaleX(${running ? effort : 0})` }} />
      </div>
    </div>
  );
}

/** Start, skip and stop the protocol (the block's actions); full screen when offered. */
function ProtocolControls({
  invoke,
  onFullscreen,
}: {
  invoke: (action: string) => void;
  onFullscreen: (() => void) | undefined;
}) {
  return (
    <div className="stimulus__controls" aria-label="Protocol controls">
      <button type="button" onClick={() => invoke("start")}>
        Start protocol
      </button>
      <button type="button" onClick={() => invoke("skip")}>
        Skip phase
      </button>
      <button type="button" onClick={() => invoke("stop")}>
        Stop protocol
      </button>
      {onFullscreen ? (
        <button type="button" onClick={onFullscreen}>
          Full screen
        </button>
      ) : null}
    </div>
  );
}

/** The stimulus view over the whole window (and the screen, when the browser allows). */
export function StimulusOverlay({ block, onClose }: { block: BlockInfo; onClose(): void }) {
  const ref = useRef<HTMLDivElement>(null);
  useEffect(() => {
    const el = ref.current;
    el?.focus();
    if (el?.requestFullscreen) el.requestFullscreen().catch(() => {});
    const onKey = (e: KeyboardEvent): void => {
      if (e.key === "Escape") onClose();
    };
    window.addEventListener("keydown", onKey);
    return () => {
      window.removeEventListener("keydown", onKey);
      if (document.fullscreenElement) void document.exitFullscreen().catch(() => {});
    };
  }, [onClose]);
  return (
    <div
      ref={ref}
      className="stimulus-overlay"
      role="dialog"
      aria-modal="true"
      aria-label={`Stimulus ${block.name}`}
      tabIndex={-1}
    >
      <button type="button" className="stimulus-overlay__close" onClick={onClose}>
        Close <kbd>Esc</kbd>
      </button>
      <StimulusView block={block} visible large />
    </div>
  );
}
