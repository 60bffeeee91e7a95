/**
 * A bare page for the UI benchmark and for looking at panels on their own: the browser build's
 * engine worker runs a pipeline and BlockPanels of the chosen blocks are mounted side by side,
 * without the app shell. `harness.html?pipeline=pipelines/bench/delsys.yaml&blocks=A,B&tab=scope`.
 * Served from the same folder as the browser build (it uses its engine.worker.js, WASM and
 * pipelines).
 */
import { createRoot } from "react-dom/client";
import { useState } from "react";
import "../../../app/ui/styles.css";
import type { BlockInfo } from "../../../app/engine/protocol";
import { EngineClient } from "../../../app/ui/client/engine-client";
import { EngineContext } from "../../../app/ui/client/hooks";
import { BlockPanel } from "../../../app/ui/panels/block-panel";
import { workerConnection } from "../../../app/web/worker-connection";

const params = new URLSearchParams(location.search);
const file = params.get("pipeline") ?? "pipelines/bench/delsys.yaml";
const names = (params.get("blocks") ?? "Delsys,LowPass,Resampler").split(",").filter(Boolean);
const width = Number(params.get("width") ?? 480);

const client = new EngineClient(workerConnection(new URL("engine.worker.js", location.href)));
(window as unknown as { mosaic: unknown }).mosaic = { client };

function Panels({ blocks }: { blocks: BlockInfo[] }) {
  const [shown, setShown] = useState(() => new Set(blocks.map((b) => b.name)));
  const [visible, setVisible] = useState(true);
  return (
    <div style={{ padding: 8 }}>
      <p>
        <button type="button" data-harness="toggle-visible" onClick={() => setVisible(!visible)}>
          {visible ? "hide panels" : "show panels"}
        </button>{" "}
        <button type="button" data-harness="close-all" onClick={() => setShown(new Set())}>
          close panels
        </button>
      </p>
      <div style={{ display: "flex", flexWrap: "wrap", gap: 8, alignItems: "flex-start" }}>
        {blocks
          .filter((b) => shown.has(b.name))
          .map((b) => (
            <section
              key={b.name}
              className="panel-frame"
              data-panel={b.name}
              style={{ width, padding: 8 }}
            >
              <h2 style={{ margin: "0 0 4px", fontSize: 14 }}>
                {b.name} <span style={{ color: "#5b636c", fontWeight: 400 }}>{b.type}</span>
              </h2>
              <BlockPanel
                block={b}
                visible={visible}
                onClose={() => setShown((s) => new Set([...s].filter((x) => x !== b.name)))}
                onOpenStimulus={() => alert(`stimulus view of ${b.name}`)}
              />
            </section>
          ))}
      </div>
    </div>
  );
}

async function main(): Promise<void> {
  const root = createRoot(document.getElementById("root")!);
  const source = await (await fetch(file)).text();
  const r = await client.load(file, source);
  if (!r.graph) {
    root.render(<pre>{JSON.stringify(r, null, 2)}</pre>);
    return;
  }
  const blocks = names
    .map((n) => r.graph!.blocks.find((b) => b.name === n))
    .filter((b): b is BlockInfo => b !== undefined);
  root.render(
    <EngineContext.Provider value={client}>
      <Panels blocks={blocks} />
    </EngineContext.Provider>,
  );
  if (params.get("start") !== "false") await client.start();
}

void main();
