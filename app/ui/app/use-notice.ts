/**
 * The shell's notices: a message goes into the event log and shows for a few seconds at the
 * bottom of the page (errors longer). Files the engine saves (the browser build cannot write
 * files) are downloaded, and say so.
 */
import { useCallback, useEffect, useRef, useState } from "react";
import type { EngineClient } from "../client/engine-client";
import type { LogEntry } from "./log-book";
import { saveFile } from "./save-file";
import type { UiActions } from "./ui-context";

export interface Notice {
  text: string;
  level: "info" | "error";
  id: number;
}

export type Notify = UiActions["notify"];

export function useNotice(
  client: EngineClient,
  addLog: (e: Omit<LogEntry, "id">) => void,
): { notice: Notice | null; notify: Notify } {
  const [notice, setNotice] = useState<Notice | null>(null);
  const nextId = useRef(1);
  const notify = useCallback(
    (message: string, level: "info" | "error" = "info", block = "") => {
      addLog({ t: Date.now() / 1000, level, block, message });
      const text = block && !message.startsWith(block) ? `${block}: ${message}` : message;
      setNotice({ text, level, id: nextId.current++ });
    },
    [addLog],
  );
  // The browser build's engine cannot write files: what it saves comes here to be downloaded.
  useEffect(
    () =>
      client.onDownload((d) => {
        saveFile(d.name, d.mime, d.bytes);
        notify(`downloaded ${d.name}`);
      }),
    [client, notify],
  );
  useEffect(() => {
    if (!notice) return undefined;
    const id = setTimeout(() => setNotice(null), notice.level === "error" ? 8000 : 4000);
    return () => clearTimeout(id);
  }, [notice]);
  return { notice, notify };
}
