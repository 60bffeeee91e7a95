/**
 * A predictor's model file, from its panel: _Save model_ runs the block's `save` action (a
 * download in the browser build, where the engine cannot write files; the host's folder
 * otherwise) and _Load model from file…_ reads a model file the user picks in the page and hands
 * its text to the block's `load` action, so a model reaches an engine that cannot read the
 * user's disk (the browser build, or a `mosaic serve` on another machine).
 */
import { useRef, useState, type ChangeEvent, type ReactNode } from "react";
import type { BlockInfo } from "../../engine/protocol";
import { useEngine, useEngineState } from "../client/hooks";

/**
 * The biggest model file sent (within the 8 MiB a message to mosaic serve may hold: a ridge
 * model of some 600 features, an RFF model of D ≈ 600).
 */
const MAX_MODEL_BYTES = 7 * 1024 * 1024;

export function ModelFileControls({ block }: { block: BlockInfo }): ReactNode {
  const client = useEngine();
  const loaded = useEngineState() !== "empty";
  const input = useRef<HTMLInputElement>(null);
  const [reply, setReply] = useState<{ ok: boolean; message: string } | null>(null);
  const has = (name: string) => block.actions.some((a) => a.name === name);
  if (!has("save") && !has("load")) return null;

  const run = async (action: string, arg?: unknown): Promise<void> => {
    setReply(null);
    const r = await client.invoke(block.name, action, arg);
    setReply({ ok: r.ok, message: r.message ?? (r.ok ? "done" : "failed") });
  };
  const onPick = async (e: ChangeEvent<HTMLInputElement>): Promise<void> => {
    const file = e.target.files?.[0];
    e.target.value = "";
    if (!file) return;
    if (file.size > MAX_MODEL_BYTES) {
      setReply({
        ok: false,
        message: `${file.name} has ${file.size} bytes; a model file sent from the page may have at most ${MAX_MODEL_BYTES}`,
      });
      return;
    }
    await run("load", { name: file.name, text: await file.text() });
  };

  return (
    <div className="mp-model" aria-label="Model file" role="group">
      <div className="mp-toolbar">
        {has("save") && (
          <button
            type="button"
            className="mp-btn"
            disabled={!loaded}
            onClick={() => void run("save")}
          >
            Save model
          </button>
        )}
        {has("load") && (
          <button
            type="button"
            className="mp-btn"
            disabled={!loaded}
            onClick={() => input.current?.click()}
          >
            Load model from file…
          </button>
        )}
        <input
          ref={input}
          type="file"
          accept=".json,application/json"
          hidden
          aria-label="Model file to load"
          onChange={(e) => void onPick(e)}
        />
      </div>
      {reply && (
        <p className={reply.ok ? "mp-ok" : "mp-error"} role={reply.ok ? "status" : "alert"}>
          {reply.message}
        </p>
      )}
    </div>
  );
}
