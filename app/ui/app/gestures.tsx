/**
 * Keyboard-driven simulated EMG: keys 1–8 hold a gesture on every EmgSimulator block of the
 * pipeline (1 rest, 2 fist, … in the simulator's order), 0 or Space go back to rest. Keys typed
 * into a field, or with a modifier, are left alone. The legend shows the keys and the gesture
 * held now.
 */
import { useEffect, useMemo } from "react";
import type { BlockInfo, GraphInfo } from "../../engine/protocol";
import type { EngineClient } from "../client/engine-client";
import { useTelemetrySelector } from "../client/hooks";
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

export function useGestureKeys(
  client: EngineClient,
  graph: GraphInfo | undefined,
  onResult: (message: string, ok: boolean, block: string) => void,
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
        void client.invoke(sim.name, "setGesture", g).then((r) => {
          onResult(r.message ?? (r.ok ? `gesture: ${g}` : "failed"), r.ok, sim.name);
        });
      }
      if (any) e.preventDefault();
    };
    window.addEventListener("keydown", onKey);
    return () => window.removeEventListener("keydown", onKey);
  }, [client, graph, onResult]);
}

/** The legend of the gesture keys, with the gesture the (first) simulator holds now. */
export function GestureLegend({ graph }: { graph: GraphInfo | undefined }) {
  const sims = useMemo(() => simulators(graph), [graph]);
  const first = sims[0];
  const names = useMemo(() => (first ? gestureNames(first) : []), [first]);
  const current = useTelemetrySelector((t) => {
    const text = t?.blocks.find((b) => b.name === first?.name)?.text ?? "";
    const word = text.split(" ")[0] ?? "";
    return names.includes(word) ? word : "";
  }, Object.is);
  if (!first) return null;
  return (
    <section className="gestures" aria-label="Simulated gestures (keyboard)">
      <h2 className="gestures__title">
        Gesture keys
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
            <kbd>{i + 1}</kbd> {n}
          </li>
        ))}
        <li>
          <kbd>0</kbd>/<kbd>Space</kbd> rest
        </li>
      </ol>
    </section>
  );
}
