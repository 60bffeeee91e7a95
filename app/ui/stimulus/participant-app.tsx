/**
 * The participant window's page (`?view=participant&block=NAME`): only the participant screen of
 * one Stimulus block, following the engine the clinician's window runs (over `mosaic serve`'s
 * socket, the desktop app's IPC or, in the browser build, the clinician page's relay). It never
 * loads or starts anything. Double-click (or F11) makes it full screen.
 */
import { useCallback, useEffect, useRef, useState, useSyncExternalStore } from "react";
import type { BlockInfo, GraphInfo } from "../../engine/protocol";
import type { EngineClient } from "../client/engine-client";
import { EngineContext, useEngine } from "../client/hooks";
import { ParticipantScreen } from "./participant-screen";
import { heldOutTrigger } from "./test-schedule";
import "./participant.css";

/** The Stimulus block to show: the one named, else the pipeline's first. */
export function participantBlock(
  graph: GraphInfo | undefined,
  name: string | undefined,
): BlockInfo | undefined {
  const stimuli = graph?.blocks.filter((b) => b.type === "Stimulus") ?? [];
  return name !== undefined ? stimuli.find((b) => b.name === name) : stimuli[0];
}

function Message({ text, detail }: { text: string; detail?: string }) {
  return (
    <div className="participant participant--waiting" data-screen="waiting">
      <header className="participant__top" />
      <main className="participant__main">
        <div className="participant__wait">
          {text}
          {detail ? <p className="participant__detail">{detail}</p> : null}
        </div>
      </main>
    </div>
  );
}

function toggleFullscreen(): void {
  if (document.fullscreenElement) void document.exitFullscreen().catch(() => {});
  else void document.documentElement.requestFullscreen?.().catch(() => {});
}

/**
 * The client's connection and graph, read again once subscribed: the first answers may come
 * before an effect would subscribe (the browser build's relay answers within the same task).
 */
function useClientView(): { connected: boolean; graph: GraphInfo | undefined } {
  const client = useEngine();
  const subscribe = useCallback(
    (changed: () => void) => {
      const offs = [client.onHello(changed), client.onGraph(changed)];
      return () => offs.forEach((off) => off());
    },
    [client],
  );
  const connected = useSyncExternalStore(subscribe, () => client.connected);
  const graph = useSyncExternalStore(subscribe, () => client.graph);
  return { connected, graph };
}

/** A number that changes with every new graph (a load starts the screen afresh). */
function useGeneration(graph: GraphInfo | undefined): number {
  const seen = useRef<{ graph: GraphInfo | undefined; n: number }>({ graph, n: 0 });
  if (seen.current.graph !== graph) seen.current = { graph, n: seen.current.n + 1 };
  return seen.current.n;
}

/** Where the engine is lent by another page (the browser build): whether that page is there. */
export interface EngineLink {
  onLink(listener: (up: boolean) => void): () => void;
}

/** False once the lending page said it closed; true again when it comes back. */
function useLinkUp(link: EngineLink | undefined): boolean {
  const [up, setUp] = useState(true);
  useEffect(() => link?.onLink(setUp), [link]);
  return up;
}

function ParticipantRoot({
  name,
  problem,
  link,
}: {
  name: string | undefined;
  problem?: string;
  link?: EngineLink;
}) {
  const { connected, graph } = useClientView();
  const up = useLinkUp(link);
  const block = participantBlock(graph, name);
  const generation = useGeneration(graph);
  useEffect(() => {
    document.title = "Participant — MOSAIC";
    document.body.classList.add("participant-page");
    window.addEventListener("dblclick", toggleFullscreen);
    return () => window.removeEventListener("dblclick", toggleFullscreen);
  }, []);
  if (problem !== undefined) return <Message text="Not connected" detail={problem} />;
  if (!up) {
    return (
      <Message
        text="Please wait"
        detail="The clinician's MOSAIC window was closed; this one follows it again when it reopens."
      />
    );
  }
  if (!connected) {
    return (
      <Message
        text="Connecting…"
        detail="This window follows the clinician's MOSAIC window: keep that one open."
      />
    );
  }
  if (!block) return <Message text="Please wait" detail="The session has not been set up yet." />;
  return (
    <ParticipantScreen
      key={`${block.name}:${generation}`}
      block={block}
      test={heldOutTrigger(graph)}
    />
  );
}

export function ParticipantApp({
  client,
  block,
  problem,
  link,
}: {
  client: EngineClient;
  /** The Stimulus block's name (the pipeline's first Stimulus when undefined). */
  block: string | undefined;
  /** Why this page has no engine to follow (said on the screen). */
  problem?: string;
  /** The browser build's relay: says when the clinician's page closes. */
  link?: EngineLink;
}) {
  return (
    <EngineContext.Provider value={client}>
      <ParticipantRoot
        name={block}
        {...(problem !== undefined ? { problem } : {})}
        {...(link !== undefined ? { link } : {})}
      />
    </EngineContext.Provider>
  );
}
