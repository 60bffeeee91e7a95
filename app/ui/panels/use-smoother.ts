/**
 * The Smoother of a spider or heatmap view as a hook (one per number of values, told the latest
 * settings).
 */
import { useEffect, useMemo } from "react";
import { Smoother, type Reduce } from "./channels";

/** One Smoother per number of values, following the settings; reset when the reduction changes. */
export function useSmoother(n: number, reduce: Reduce, tauS: number): Smoother {
  const smoother = useMemo(() => new Smoother(n, reduce, tauS), [n]);
  smoother.mode = reduce;
  smoother.tauS = tauS;
  useEffect(() => smoother.reset(), [reduce, smoother]);
  return smoother;
}
