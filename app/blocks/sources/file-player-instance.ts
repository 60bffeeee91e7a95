/** FilePlayer: the block instance of a player, the runtime's calls and the panel's actions. */
import type { BlockInstance } from "../../engine";
import type { PlayerRun } from "./file-player-run";

export function playerInstance(run: PlayerRun): BlockInstance {
  return {
    start: () => run.start(),
    stop: () => run.stop(),
    process: (f) => run.process(f),
    reset: () => run.reset(),
    dispose: () => run.dispose(),
    setParam(name, value) {
      if (name === "Speed") run.setSpeed(value as number);
      else if (name === "Loop") run.setLoop(value as boolean);
    },
    actions: {
      restart: {
        label: "Restart",
        description: "Play again from the first row",
        run: () => run.restart(),
      },
      pause: {
        label: "Pause",
        description: "Stop emitting rows until resumed",
        run: () => run.pause(),
      },
      seek: {
        label: "Seek",
        description: "Jump to a time: seconds from the recording's first row (argument)",
        run: (arg?: unknown) => run.seek(arg),
      },
      resume: {
        label: "Resume",
        description: "Continue from the row where it paused",
        run: () => run.resume(),
      },
    },
  };
}
