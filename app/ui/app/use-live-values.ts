/**
 * The live values that are not the file's (issue 17, defect 1), and the shell's "Write live
 * values back to the file": the pipeline's text gets them through the document model (comments
 * and formatting kept), the page downloads it (the browser cannot write files), and the engine
 * is told, so that every client's "changed since loaded" markers clear.
 */
import { useCallback, useEffect, useRef, useState } from "react";
import type { EngineClient } from "../client/engine-client";
import { useEngine } from "../client/hooks";
import {
  describeChanges,
  liveChanges,
  writeLiveValues,
  type LiveChange,
} from "../editor/live-values";
import { saveFile } from "./save-file";

/** The live params changed since loaded, kept current as any client changes them. */
export function useLiveChanges(): LiveChange[] {
  const client = useEngine();
  const [changes, setChanges] = useState(() => liveChanges(client.graph));
  useEffect(() => {
    const update = (): void => setChanges(liveChanges(client.graph));
    update();
    const offParams = client.onParams(update);
    const offGraph = client.onGraph(update);
    const offRemote = client.onRemoteGraph(update);
    return () => {
      offParams();
      offGraph();
      offRemote();
    };
  }, [client]);
  return changes;
}

type Notify = (message: string, level?: "info" | "error") => void;

/**
 * The action: `text()` is the pipeline's text the page holds (undefined: none, e.g. a file
 * opened elsewhere whose text the engine did not send).
 */
export function useWriteLiveValues(
  client: EngineClient,
  text: () => { file: string; source: string } | undefined,
  notify: Notify,
): () => void {
  const textRef = useRef(text);
  textRef.current = text;
  return useCallback(() => {
    void writeBack(client, textRef.current(), notify);
  }, [client, notify]);
}

async function writeBack(
  client: EngineClient,
  doc: { file: string; source: string } | undefined,
  notify: Notify,
): Promise<void> {
  const changes = liveChanges(client.graph);
  if (changes.length === 0) {
    notify("Every live value is already the file's");
    return;
  }
  if (doc === undefined) {
    notify("Cannot write the live values: this page does not have the pipeline's text", "error");
    return;
  }
  let result: ReturnType<typeof writeLiveValues>;
  try {
    result = writeLiveValues(doc.source, doc.file, changes);
  } catch (e) {
    notify(`Cannot write the live values: ${(e as Error).message}`, "error");
    return;
  }
  const name = doc.file.split("/").pop() || "pipeline.yaml";
  const skipped = result.skipped.map((s) => `${s.change.block}.${s.change.param}: ${s.reason}`);
  if (result.written.length > 0) {
    saveFile(name, "text/yaml", new TextEncoder().encode(result.text));
    const values = result.written.map(({ block, param, value }) => ({ block, param, value }));
    const r = await client.paramsWritten(result.text, values);
    if (!r.ok) {
      notify(`The engine refused the written values: ${r.message ?? "unknown reason"}`, "error");
      return;
    }
    notify(`Wrote ${describeChanges(result.written)} into ${name} (downloaded)`);
  }
  if (skipped.length > 0) notify(`Not written: ${skipped.join("; ")}`, "error");
}
