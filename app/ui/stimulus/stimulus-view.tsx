/**
 * The participant's view of a Stimulus block (paper III-G): the current cue in large type, what
 * to do now (relax, get ready, hold, release), a progress bar of the phase and the time left; the
 * target ramp as an effort gauge. Built from the block's `cue`, `phase` and `target` outputs
 * (watched while visible) and its status text. `StimulusOverlay` shows it full screen.
 */
import { useCallback, useEffect, useMemo, useRef, useState } from "react";
import type { BlockInfo, DataMessage } from "../../engine/protocol";
import { useBlockData, useEngine, useTelemetrySelector } from "../client/hooks";
import { PHASES, cueLabels, type Phase } from "./cues";

const PHASE_PARAM: Record<Phase, string | undefined> = {
  rest: "Rest",
  rise: "Rise",
  hold: "Hold",
  capture: "Capture",
  fall: "Fall",
  end: undefined,
};
const PHASE_DEFAULT: Record<Phase, number> = {
  rest: 2,
  rise: 1,
  hold: 2,
  capture: 5,
  fall: 1,
  end: 0,
};

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

interface Live {
  phase: Phase | undefined;
  cue: number;
  /** Event time of the phase's first event seen (NaN: the phase started before we watched). */
  phaseStart: number;
  /** Latest event time, and when it arrived (performance.now()). */
  lastT: number;
  arrived: number;
  /** |target| relative to the cue's full target, 0..1. */
  effort: number;
}

const parseLeft = (text: string): number => {
  const m = /([\d.]+) s left/.exec(text);
  return m ? Number(m[1]) : NaN;
};
/** The cue's label from the status text ("hold: fist (2 of 10), 1.5 s left"). */
const parseLabel = (text: string): string => {
  const m = /^(?:rise|hold|capture|fall): (.+) \(\d+ of \d+\)/.exec(text);
  return m ? m[1]! : "";
};
const parseCount = (text: string): string => {
  const m = /\((\d+ of \d+)\)/.exec(text);
  return m ? m[1]! : "";
};

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
  const [live, setLive] = useState<Live>({
    phase: undefined,
    cue: NaN,
    phaseStart: NaN,
    lastT: NaN,
    arrived: 0,
    effort: 0,
  });
  const peak = useRef(1e-12);

  const onPhase = useCallback((m: DataMessage) => {
    setLive((p) => {
      let { phase, phaseStart } = p;
      for (let i = 0; i < m.t.length; i++) {
        const ph = PHASES[m.v[i * m.cols]!] ?? undefined;
        if (ph !== phase) {
          // The first phase we see may have started before we watched: its start is unknown.
          phaseStart = phase === undefined ? NaN : m.t[i]!;
          phase = ph;
        }
      }
      return {
        ...p,
        phase,
        phaseStart,
        lastT: m.t[m.t.length - 1]!,
        arrived: performance.now(),
      };
    });
  }, []);
  const onCue = useCallback((m: DataMessage) => {
    const c = m.v[(m.t.length - 1) * m.cols]!;
    setLive((p) => (Object.is(p.cue, c) ? p : { ...p, cue: c }));
  }, []);
  const onTarget = useCallback((m: DataMessage) => {
    const n = m.t.length;
    const off = (n - 1) * m.cols;
    let mx = 0;
    for (let k = 0; k < m.cols; k++) mx = Math.max(mx, Math.abs(m.v[off + k]!));
    for (let i = 0; i < n * m.cols; i++) peak.current = Math.max(peak.current, Math.abs(m.v[i]!));
    const effort = mx / peak.current;
    setLive((p) => (Math.abs(p.effort - effort) < 0.005 ? p : { ...p, effort }));
  }, []);
  useBlockData(block.name, "phase", onPhase, visible, 50);
  useBlockData(block.name, "cue", onCue, visible, 50);
  useBlockData(block.name, "target", onTarget, visible, 20);

  const text = useTelemetrySelector(
    (t) => t?.blocks.find((b) => b.name === block.name)?.text ?? "",
    Object.is,
  );

  // Smooth countdown between data messages (20 Hz), unless reduced motion is asked for.
  const [, tick] = useState(0);
  useEffect(() => {
    if (!visible || live.phase === undefined || live.phase === "end") return undefined;
    const id = window.setInterval(() => tick((n) => n + 1), 100);
    return () => window.clearInterval(id);
  }, [visible, live.phase]);

  // Data stops when the protocol is not running: then the status text says what is going on.
  const stale = live.arrived === 0 || performance.now() - live.arrived > 600;
  const running = !stale && live.phase !== undefined && live.phase !== "end";
  const phase = running ? live.phase : stale ? undefined : live.phase;
  // The cue and phase streams arrive as separate messages: until the cue of a new phase is in,
  // the status text names it.
  const label = Number.isFinite(live.cue)
    ? (labels[live.cue] ?? `cue ${live.cue + 1}`)
    : parseLabel(text);
  const param = phase ? PHASE_PARAM[phase] : undefined;
  const p = block.params[param ?? ""];
  const duration = typeof p === "number" ? p : phase ? PHASE_DEFAULT[phase] : 0;
  const now = live.lastT + (performance.now() - live.arrived) / 1000;
  let left = Number.isNaN(live.phaseStart)
    ? parseLeft(text)
    : Math.max(0, live.phaseStart + duration - now);
  if (!running) left = NaN;
  const progress =
    duration > 0 && Number.isFinite(left) ? Math.min(1, Math.max(0, 1 - left / duration)) : 0;
  const count = parseCount(text);

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
      <div className="stimulus__footer">
        <span className="stimulus__left" data-left={Number.isFinite(left) ? left.toFixed(1) : ""}>
          {Number.isFinite(left) ? `${left.toFixed(1)} s left` : " "}
        </span>
        <div className="stimulus__effort" aria-label={`target ${Math.round(live.effort * 100)} %`}>
          <span>target</span>
          <div className="stimulus__gauge">
            <div style={{ transform: `scaleX(${running ? live.effort : 0})` }} />
          </div>
        </div>
      </div>
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
