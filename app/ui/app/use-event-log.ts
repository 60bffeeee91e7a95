/**
 * The app's event log as state (./log-book.ts): each load's report starts a new section (counts
 * reset), runtime events of the engine and the replies to actions join it. An error opens it.
 */
import { useCallback, useEffect, useRef, useState } from "react";
import type { EngineClient } from "../client/engine-client";
import {
  appendEntries,
  EMPTY_LOG,
  loadLines,
  startLoad,
  type LoadReport,
  type LogBook,
  type LogEntry,
} from "./log-book";

/** Subscribes to the reports of loads (usePipeline's `onLoadReport`); returns the unsubscribe. */
export type LoadReports = (l: (r: LoadReport) => void) => () => void;

export interface EventLogState {
  book: LogBook;
  open: boolean;
  setOpen(update: (open: boolean) => boolean): void;
  add(e: Omit<LogEntry, "id">): void;
  clear(): void;
}

export function useEventLog(client: EngineClient, loadReports: LoadReports): EventLogState {
  const [book, setBook] = useState<LogBook>(EMPTY_LOG);
  const [open, setOpenState] = useState(false);
  const nextId = useRef(1);
  const entry = useCallback(
    (e: Omit<LogEntry, "id">): LogEntry => ({ ...e, id: nextId.current++ }),
    [],
  );
  const add = useCallback(
    (e: Omit<LogEntry, "id">) => {
      const one = entry(e);
      setBook((b) => appendEntries(b, [one]));
    },
    [entry],
  );
  useEffect(
    () =>
      client.onEvent((e) => {
        add(e);
        if (e.level === "error") setOpenState(true);
      }),
    [client, add],
  );
  const onReport = useCallback(
    (r: LoadReport) => {
      const t = Date.now() / 1000;
      const lines = loadLines(r).map((l) => entry({ t, ...l }));
      const next = nextId.current;
      setBook((b) => (r.replaced ? startLoad(b, lines, next) : appendEntries(b, lines)));
      if (lines.some((l) => l.level === "error")) setOpenState(true);
    },
    [entry],
  );
  useEffect(() => loadReports(onReport), [loadReports, onReport]);
  const clear = useCallback(() => setBook(EMPTY_LOG), []);
  const setOpen = useCallback((u: (open: boolean) => boolean) => setOpenState(u), []);
  return { book, open, setOpen, add, clear };
}
