/**
 * The participant's screen (issue 17): what to do now in large type with a drawing of the
 * gesture, the next gesture while resting, where the protocol is (cue k of n, repetition, the
 * phase steps) and the time left, the held-out test cued as a test, and a clear end. No controls:
 * the clinician runs the session from the main window. Built from useParticipant's model.
 */
import type { BlockInfo } from "../../engine/protocol";
import { GesturePicture } from "./gesture-picture";
import type { ParticipantModel } from "./participant-model";
import { useParticipant } from "./use-participant";
import "./participant.css";

const STEPS = ["rise", "hold", "capture", "fall"] as const;
const STEP_NAME: Record<(typeof STEPS)[number], string> = {
  rise: "get ready",
  hold: "hold",
  capture: "recording",
  fall: "release",
};

const isTest = (m: ParticipantModel): boolean => m.screen.startsWith("test-");

function TopBar({ model }: { model: ParticipantModel }) {
  const test = isTest(model);
  const mode = model.screen === "end" ? "" : test ? "Test" : model.phase ? "Training" : "";
  return (
    <header className="participant__top">
      <span className={`participant__mode${test ? " is-test" : ""}`}>{mode}</span>
      <span className="participant__count">
        {[model.count, model.repetition].filter((s) => s !== "").join("  ·  ")}
      </span>
    </header>
  );
}

function NextUp({ label }: { label: string | undefined }) {
  if (label === undefined) return null;
  return (
    <div className="participant__next" data-next={label}>
      <span className="participant__next-title">Next</span>
      <GesturePicture label={label} size="small" />
      <span className="participant__next-label">{label}</span>
    </div>
  );
}

function Steps({ model }: { model: ParticipantModel }) {
  if (model.screen !== "cue") return null;
  return (
    <ol className="participant__steps" aria-label="Steps">
      {STEPS.map((s) => (
        <li
          key={s}
          className={s === model.phase ? "is-current" : undefined}
          aria-current={s === model.phase ? "step" : undefined}
        >
          {STEP_NAME[s]}
        </li>
      ))}
    </ol>
  );
}

function Centre({ model }: { model: ParticipantModel }) {
  switch (model.screen) {
    case "cue":
    case "test-cue":
      return (
        <div className="participant__cue">
          <GesturePicture label={model.gesture ?? ""} />
          <div className="participant__words">
            <div className="participant__gesture">{model.gesture}</div>
            <div className="participant__instruction">{model.instruction}</div>
            <Steps model={model} />
          </div>
        </div>
      );
    case "rest":
    case "test-rest":
    case "test-ready":
      return (
        <div className="participant__rest">
          {model.screen === "test-ready" ? (
            <p className="participant__test-note">
              Test: make each gesture when it is shown. Nothing is learned now.
            </p>
          ) : null}
          <div className="participant__relax">{model.instruction}</div>
          <NextUp label={model.next} />
        </div>
      );
    case "end":
      return (
        <div className="participant__end">
          <svg viewBox="0 0 100 100" className="participant__check" aria-hidden="true">
            <circle cx="50" cy="50" r="46" />
            <path d="M28 52 L44 67 L73 36" />
          </svg>
          <div className="participant__done">All done</div>
          <div className="participant__instruction">{model.instruction}</div>
        </div>
      );
    default:
      return <div className="participant__wait">{model.instruction}</div>;
  }
}

function Countdown({ model }: { model: ParticipantModel }) {
  const known = Number.isFinite(model.left);
  return (
    <footer className="participant__bottom">
      <div
        className="participant__progress"
        role="progressbar"
        aria-label="Time in this step"
        aria-valuemin={0}
        aria-valuemax={100}
        aria-valuenow={Math.round(model.progress * 100)}
      >
        <div className="participant__bar" style={{ transform: `scaleX(${model.progress})` }} />
      </div>
      <span className="participant__left" data-left={known ? model.left.toFixed(1) : ""}>
        {known ? `${Math.ceil(model.left)} s` : ""}
      </span>
    </footer>
  );
}

/** The screen itself, for a model (also used by tests and previews). */
export function ParticipantView({ model, block }: { model: ParticipantModel; block: string }) {
  return (
    <div
      className={`participant participant--${model.screen}`}
      data-participant={block}
      data-screen={model.screen}
      data-phase={model.phase ?? "none"}
      data-gesture={model.gesture ?? ""}
      data-next={model.next ?? ""}
      data-count={model.count}
    >
      <TopBar model={model} />
      <main className="participant__main" aria-live="polite">
        <Centre model={model} />
      </main>
      {model.screen === "end" || model.screen === "waiting" ? null : <Countdown model={model} />}
    </div>
  );
}

/** The participant screen of a Stimulus block, following the engine. */
export function ParticipantScreen({
  block,
  test,
}: {
  block: BlockInfo;
  /** The Trigger that plays the held-out test (test-schedule.ts), if any. */
  test: BlockInfo | undefined;
}) {
  const model = useParticipant(block, test);
  return <ParticipantView model={model} block={block.name} />;
}
