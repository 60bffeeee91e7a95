/**
 * Keyboard-driven simulated EMG: keys 1–8 hold a gesture on every EmgSimulator block of the
 * pipeline (1 rest, 2 fist, … in the simulator's order), 0 or Space go back to rest. Keys typed
 * into a field, or with a modifier, are left alone. The legend shows the keys and the gesture
 * held now; each of its entries is also a button (mouse and touch demos) that holds the gesture
 * on every simulator that knows it.
 */
import { useEffect, useMemo } from "react";
import type { BlockInfo, GraphInfo } from "../../engine/protocol";
import type { EngineClient } from "../client/engine-client";
import { useEngine, useTelemetrySelector } from "../client/hooks";
import { gestureForKey, gestureNames } from "./gesture-names";

function typingInto(target: EventTarget | null): boolean {
  if (!(target instanceof HTMLElement)) return false;
  if (target.isContentEditable) return true;
  const tag = target.tagName;
  return tag === "INPUT" || tag === "TEXTAREA" || tag === "SELECT";
}

export function simulators(graph: GraphInfo | undefined): BlockInfo[] {
  return graph?.blocks.filter((b) => b.type === "EmgSimulator") ?? [];
}

/** What the page does with the reply to a gesture (a failure is shown, a success logged). */
export type GestureResult = (message: string, ok: boolean, block: string) => void;

/** Holds `gesture` on one simulator through its `setGesture` action. */
function holdGesture(
  client: EngineClient,
  sim: BlockInfo,
  gesture: string,
  onResult: GestureResult,
): void {
  void client.invoke(sim.name, "setGesture", gesture).then((r) => {
    onResult(r.message ?? (r.ok ? `gesture: ${gesture}` : "failed"), r.ok, sim.name);
  });
}

export function useGestureKeys(
  client: EngineClient,
  graph: GraphInfo | undefined,
  onResult: GestureResult,
): void {
  useEffect(() => {
    const sims = simulators(graph);
    if (sims.length === 0) return undefined;
    const onKey = (e: KeyboardEvent): void => {
      if (e.ctrlKey || e.metaKey || e.altKey || e.repeat || typingInto(e.target)) return;
      // Space on a button or a menu item activates it; only digits work everywhere.
      if (
        e.key === " " &&
        e.target instanceof HTMLElement &&
        e.target.closest("button, [role=menuitem], a")
      )
        return;
      let any = false;
      for (const sim of sims) {
        const g = gestureForKey(e.key, gestureNames(sim));
        if (g === undefined) continue;
        any = true;
        holdGesture(client, sim, g, onResult);
      }
      if (any) e.preventDefault();
    };
    window.addEventListener("keydown", onKey);
    return () => window.removeEventListener("keydown", onKey);
  }, [client, graph, onResult]);
}

/**
 * The legend of the gesture keys, with the gesture the (first) simulator holds now. Every entry
 * is a button: a click or a tap holds that gesture on every simulator that has it.
 */
export function GestureLegend({
  graph,
  onResult,
}: {
  graph: GraphInfo | undefined;
  onResult: GestureResult;
}) {
  const client = useEngine();
  const sims = useMemo(() => simulators(graph), [graph]);
  const first = sims[0];
  const names = useMemo(() => (first ? gestureNames(first) : []), [first]);
  const current = useTelemetrySelector((t) => {
    const text = t?.blocks.find((b) => b.name === first?.name)?.text ?? "";
    const word = text.split(" ")[0] ?? "";
    return names.includes(word) ? word : "";
  }, Object.is);
  if (!first) return null;
  const hold = (gesture: string): void => {
    for (const sim of sims) {
      if (gestureNames(sim).includes(gesture)) holdGesture(client, sim, gesture, onResult);
    }
  };
  const rest = gestureForKey("0", names);
  return (
    <section className="gestures" aria-label="Simulated gestures (keys or buttons)">
      <h2 className="gestures__title">
        Gestures
        <span className="gestures__sub">
          {sims.length === 1 ? first.name : `${sims.length} simulators`}
        </span>
      </h2>
      <ol className="gestures__list">
        {names.slice(0, 9).map((n, i) => (
          <li
            key={n}
            className={n === current ? "is-current" : undefined}
            aria-current={n === current ? "true" : undefined}
            data-gesture={n}
          >
            <GestureButton gesture={n} keys={[String(i + 1)]} held={n === current} hold={hold} />
          </li>
        ))}
        {rest !== undefined ? (
          <li>
            <GestureButton gesture={rest} keys={["0", "Space"]} held={false} hold={hold} />
          </li>
        ) : null}
      </ol>
    </section>
  );
}

/** One gesture of the legend: its key and name, a button that holds it. */
function GestureButton({
  gesture,
  keys,
  held,
  hold,
}: {
  gesture: string;
  keys: readonly string[];
  held: boolean;
  hold: (gesture: string) => void;
}) {
  return (
    <button
      type="button"
      className="gestures__btn"
      aria-pressed={held}
      title={`Hold ${gesture} (key ${keys.join(" or ")})`}
      onClick={() => hold(gesture)}
    >
      {keys.map((k, i) => (
        <span key={k}>
          {i > 0 ? "/" : ""}
          <kbd>{k}</kbd>
        </span>
      ))}{" "}
      {gesture}
    </button>
  );
}
