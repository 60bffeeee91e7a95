/**
 * The pipeline is shown whole when the edit canvas opens and when it was replaced (a template);
 * never while blocks are added, so that a drop stays where it was dropped. Empty: zoom 1.
 */
import { useNodesInitialized, useReactFlow } from "@xyflow/react";
import { useEffect, useRef } from "react";

export function useCanvasFit(empty: boolean, fitKey: number, nodeCount: number): void {
  const flow = useReactFlow();
  const fitPending = useRef(!empty);
  const lastFit = useRef(fitKey);
  if (lastFit.current !== fitKey) {
    lastFit.current = fitKey;
    fitPending.current = !empty;
  }
  const initialized = useNodesInitialized();
  useEffect(() => {
    if (empty) void flow.setViewport({ x: 40, y: 40, zoom: 1 });
  }, [empty, flow]);
  useEffect(() => {
    if (!fitPending.current || !initialized || nodeCount === 0) return;
    fitPending.current = false;
    void flow.fitView({ padding: 0.15, maxZoom: 1 });
  }, [initialized, nodeCount, flow, fitKey]);
}
