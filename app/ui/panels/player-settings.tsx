/**
 * A FilePlayer's live params in its Player view: Speed (presets, or the file's value) and Loop,
 * shown at once and put back when the engine refuses them.
 */
import { useState, type ReactNode } from "react";
import type { BlockInfo } from "../../engine/protocol";
import { useEngine } from "../client/hooks";

const SPEEDS = [0.25, 0.5, 1, 2, 4];

export function PlayerSettings({
  block,
  onReply,
}: {
  block: BlockInfo;
  onReply: (r: { ok: boolean; message: string }) => void;
}): ReactNode {
  const client = useEngine();
  const [speed, setSpeed] = useState(Number(block.params.Speed ?? 1));
  const [loop, setLoop] = useState(block.params.Loop === true);
  const set = async (param: string, value: unknown): Promise<boolean> => {
    const r = await client.setParam(block.name, param, value);
    onReply({ ok: r.ok, message: r.message ?? (r.ok ? `${param}: ${String(value)}` : "failed") });
    return r.ok;
  };
  const options = SPEEDS.includes(speed) ? SPEEDS : [...SPEEDS, speed].sort((a, b) => a - b);
  return (
    <div className="mp-toolbar">
      <label className="mp-field">
        Speed
        <select
          value={String(speed)}
          onChange={(e) => {
            const v = Number(e.target.value);
            const was = speed;
            setSpeed(v);
            void set("Speed", v).then((ok) => ok || setSpeed(was));
          }}
        >
          {options.map((s) => (
            <option key={s} value={String(s)}>
              {s}×
            </option>
          ))}
        </select>
      </label>
      <label className="mp-field mp-check">
        <input
          type="checkbox"
          checked={loop}
          onChange={(e) => {
            const v = e.target.checked;
            setLoop(v);
            void set("Loop", v).then((ok) => ok || setLoop(!v));
          }}
        />
        Loop
      </label>
    </div>
  );
}
