/** A block's status as a small coloured icon with its word (for panel headers). */
import type { Telemetry } from "../../engine/runtime/runtime";
import { useTelemetrySelector } from "../client/hooks";
import { StatusIcon, statusText, type Status } from "../graph/status";
import { useEngineState } from "../client/hooks";

const select = (t: Telemetry | undefined, block: string): string => {
  const b = t?.blocks.find((x) => x.name === block);
  return b ? `${b.status}:${b.stumbling}` : "idle:false";
};

export function StatusDot({ block }: { block: string }) {
  const running = useEngineState() === "running";
  const key = useTelemetrySelector((t) => select(t, block), Object.is);
  const [s, st] = key.split(":") as [Status, string];
  const status: Status = running ? s : "idle";
  const label = statusText(status, running && st === "true");
  return (
    <span className={`status-dot status-${status}`} title={label}>
      <StatusIcon status={status} />
      <span className="sr-only">{label}</span>
    </span>
  );
}
