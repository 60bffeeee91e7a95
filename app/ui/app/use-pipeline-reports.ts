/** What each load reported, for usePipeline's listeners (the log book). */
import { useCallback, useRef } from "react";
import type { LoadReport } from "./log-book";

export interface LoadReports {
  /** Tells every listener, synchronously. */
  report: (r: LoadReport) => void;
  /**
   * What each load reported (diagnostics, a problem outside the file), told synchronously when
   * its reply arrives: before any runtime event of the pipeline it loaded.
   */
  onLoadReport: (l: (r: LoadReport) => void) => () => void;
}

export function useLoadReports(): LoadReports {
  const reportListeners = useRef(new Set<(r: LoadReport) => void>());
  const report = useCallback((r: LoadReport) => {
    for (const l of reportListeners.current) l(r);
  }, []);
  const onLoadReport = useCallback((l: (r: LoadReport) => void) => {
    reportListeners.current.add(l);
    return () => {
      reportListeners.current.delete(l);
    };
  }, []);
  return { report, onLoadReport };
}
