/**
 * The toolbar's "which engine runs this pipeline" (mosaic serve at an address, this page's own
 * engine, the desktop app) and the page's notice when `mosaic serve` refused or dropped the
 * connection, with the cause in words (issue 17).
 */
import { useEffect, useState } from "react";
import {
  engineDetail,
  engineLabel,
  type ConnectionLoss,
  type EngineWhere,
} from "../client/connection-status";
import { useEngineInfo } from "../client/hooks";

/** What the page can learn about its connection's end (a `HostConnection`; none for the rest). */
export interface LossSource {
  readonly lost: ConnectionLoss | undefined;
  onLost(h: (loss: ConnectionLoss) => void): () => void;
}

/** The connection's loss, once it happened (undefined while connected or without a source). */
export function useConnectionLoss(source: LossSource | undefined): ConnectionLoss | undefined {
  const [loss, setLoss] = useState(source?.lost);
  useEffect(() => {
    if (!source) return undefined;
    setLoss(source.lost);
    return source.onLost(setLoss);
  }, [source]);
  return loss;
}

export function EngineBadge({ where }: { where: EngineWhere }) {
  const info = useEngineInfo();
  return (
    <span
      className="engine-where"
      data-engine-kind={where.kind}
      title={engineDetail(where, info.engine)}
    >
      {engineLabel(where)}
    </span>
  );
}

export function ConnectionLost({ loss }: { loss: ConnectionLoss }) {
  return (
    <p className="connection-lost" role="alert" data-refused={String(loss.refused)}>
      {loss.message}
    </p>
  );
}
