/** EmgSimulator: the block instance of a simulator, the runtime's calls and the panel's actions. */
import type { BlockInstance } from "../../engine";
import type { SimulatorRun } from "./emg-simulator-run";

export function simulatorInstance(run: SimulatorRun): BlockInstance {
  const names = run.gestures.names;
  return {
    process: (f, port) => run.process(f, port),
    reset: () => run.reset(),
    setParam(name, value) {
      if (name === "Gesture") run.setInitialGesture(value as string);
    },
    dispose: () => run.dispose(),
    actions: {
      setGesture: {
        label: "Set gesture",
        description: `Hold a gesture (stops the Sequence until reset); one of ${names.join(", ")}`,
        run: (arg?: unknown) => run.setGesture(arg),
      },
      next: {
        label: "Next gesture",
        description: "Go to the next gesture (the next Sequence step while a Sequence plays)",
        run: () => run.next(),
      },
    },
  };
}
