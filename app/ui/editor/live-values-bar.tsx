/**
 * Live values in edit mode (issue 17, defect 1): the engine may run with live values changed
 * since loading (from any tab) that the editor's text does not have. _Take live values_ sets them
 * in the text through the document model (one undoable edit, comments kept); saving a text that
 * is what runs tells the engine which of them the file now has, which clears their markers.
 */
import type { ReactNode } from "react";
import type { EngineClient } from "../client/engine-client";
import { useLiveChanges } from "../app/use-live-values";
import {
  applyLiveValues,
  describeChanges,
  liveChanges,
  missingFromText,
  presentInText,
  type LiveChange,
} from "./live-values";
import type { EditBlock } from "./model";
import type { EditorModel } from "./use-editor";

type Notify = (message: string, level?: "info" | "error") => void;

/** The editor bar's button: shown while the engine runs live values the text lacks. */
export function TakeLiveValues({
  ed,
  onNotify,
  onTaken,
}: {
  ed: EditorModel;
  onNotify: Notify;
  /** Called after the values were set in the text. */
  onTaken(): void;
}): ReactNode {
  const missing = missingFromText(useLiveChanges(), ed.blocks);
  if (missing.length === 0) return null;
  return (
    <button
      type="button"
      className="editor__take-live"
      onClick={() => {
        if (takeLiveValues(ed, missing, onNotify)) onTaken();
      }}
      title={`The engine runs with live values changed since loading that the text does not have: ${describeChanges(missing, 10)}. Set them in the text (comments kept; Undo takes them out)`}
    >
      Take live values ({missing.length})
    </button>
  );
}

/** Sets the values in the editor's text (one undoable edit); true when some were set. */
function takeLiveValues(ed: EditorModel, changes: LiveChange[], onNotify: Notify): boolean {
  let result: ReturnType<typeof applyLiveValues> | undefined;
  const e = ed.edit((doc) => {
    result = applyLiveValues(doc, changes);
  });
  if (e !== undefined || result === undefined) {
    onNotify(`Cannot take the live values: ${e ?? "no change"}`, "error");
    return false;
  }
  if (result.written.length > 0) onNotify(`Took ${describeChanges(result.written)} into the text`);
  if (result.skipped.length > 0) {
    const why = result.skipped.map((s) => `${s.change.block}.${s.change.param}: ${s.reason}`);
    onNotify(`Not taken: ${why.join("; ")}`, "error");
  }
  return result.written.length > 0;
}

/**
 * After the editor saved `text` (the text that runs): the live values it has are the file's
 * now, in every client. Nothing is sent when it has none of them.
 */
export async function savedLiveValues(
  client: EngineClient,
  text: string,
  blocks: readonly EditBlock[],
): Promise<void> {
  const values = presentInText(liveChanges(client.graph), blocks).map(
    ({ block, param, value }) => ({ block, param, value }),
  );
  if (values.length > 0) await client.paramsWritten(text, values);
}
