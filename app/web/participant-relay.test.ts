/**
 * The browser build's participant relay over real BroadcastChannels (Node has them): a clinician
 * EngineClient on a real EngineSession (test blocks, virtual clock) lends its engine to a
 * participant EngineClient on another channel object, as two windows of one origin would.
 */
import { afterEach, describe, expect, test } from "vitest";
import { VirtualClock } from "../engine/clock";
import type { DataMessage, EngineConnection, EngineMessage, UiMessage } from "../engine/protocol";
import type { Runtime } from "../engine/runtime/runtime";
import { runVirtual } from "../engine/runtime/virtual";
import { EngineSession, type LoopHooks, type SessionPlatform } from "../engine/session";
import { testCatalog } from "../engine/test-blocks";
import { noResources } from "../engine/testing";
import { EngineClient } from "../ui/client/engine-client";
import { openChannel, relayConnection, startParticipantRelay } from "./participant-relay";

const PIPELINE = `
T: { Type: Tick, DesiredRate: 100 }
C: { Type: Counter, Inputs: [T], Params: { Channels: 2 } }
`;

/** An engine session in this thread, its loop driven by the test on a virtual clock. */
function engine() {
  const clock = new VirtualClock(100);
  const handlers = new Set<(m: EngineMessage) => void>();
  const requests: UiMessage[] = [];
  let running: { rt: Runtime; hooks: LoopHooks } | undefined;
  const platform: SessionPlatform = {
    engine: "test",
    sharedMemory: false,
    clock: () => clock,
    resources: () => noResources,
    startLoop(rt, hooks) {
      running = { rt, hooks };
      return { stop: () => (running = undefined), wake: () => {} };
    },
    post: (m) => queueMicrotask(() => handlers.forEach((h) => h(m))),
  };
  const session = new EngineSession(testCatalog, platform);
  const connection: EngineConnection = {
    send: (m) => {
      requests.push(m);
      void session.handle(m);
    },
    onMessage: (h) => {
      handlers.add(h);
      return () => handlers.delete(h);
    },
    close: () => {},
  };
  const advance = (seconds: number): void => {
    const end = clock.t + seconds;
    while (running && clock.t < end - 1e-9) {
      runVirtual(running.rt, clock, Math.min(end, clock.t + running.hooks.telemetryIntervalS));
      running.hooks.onTelemetry();
    }
  };
  return { connection, requests, advance };
}

async function until(cond: () => boolean, what: string): Promise<void> {
  const end = Date.now() + 10_000;
  while (!cond()) {
    if (Date.now() > end) throw new Error(`timed out waiting for ${what}`);
    await new Promise((r) => setTimeout(r, 5));
  }
}

const closers: (() => void)[] = [];
afterEach(() => {
  for (const c of closers.splice(0)) c();
});

async function clinicianAndParticipant(channel: string) {
  const e = engine();
  const clinician = new EngineClient(e.connection);
  await until(() => clinician.connected, "the engine's hello");
  expect((await clinician.load("p.yaml", PIPELINE)).ok).toBe(true);
  expect((await clinician.start()).ok).toBe(true);
  const stop = startParticipantRelay(clinician, openChannel(channel));
  const participant = new EngineClient(relayConnection(openChannel(channel)));
  closers.push(() => participant.close(), stop);
  return { e, clinician, participant, stop };
}

describe("participant relay (browser build)", () => {
  test("a participant gets hello, the graph, the state and telemetry of the clinician's engine", async () => {
    const { e, participant } = await clinicianAndParticipant("relay-a");
    await until(() => participant.connected && participant.graph !== undefined, "hello, graph");
    expect(participant.engineName).toBe("test");
    expect(participant.graph!.blocks.map((b) => b.name)).toEqual(["T", "C"]);
    await until(() => participant.state === "running", "the running state");
    e.advance(0.2);
    await until(() => participant.telemetry !== undefined, "telemetry");
    expect(participant.telemetry!.blocks.map((b) => b.name)).toContain("C");
    // The participant's hello never reached the engine: the relay answered it.
    expect(e.requests.filter((m) => m.type === "hello")).toHaveLength(1);
  });

  test("watches are shared with the clinician's panels; other requests are refused", async () => {
    const { e, clinician, participant } = await clinicianAndParticipant("relay-b");
    await until(() => participant.connected, "hello");
    const seenByClinician: DataMessage[] = [];
    const seenByParticipant: DataMessage[] = [];
    const offClinician = clinician.watch("C", "out", (m) => seenByClinician.push(m));
    const offParticipant = participant.watch("C", "out", (m) => seenByParticipant.push(m));
    // The participant's watch crosses the channel first: run the pipeline until its data comes.
    await until(() => {
      e.advance(0.05);
      return seenByParticipant.length > 0;
    }, "data in the participant window");
    const last = seenByParticipant.at(-1)!;
    expect(last.cols).toBe(2);
    expect(last.t.length).toBeGreaterThan(0);
    // One engine watch for both windows.
    expect(e.requests.filter((m) => m.type === "watch")).toHaveLength(1);
    // The participant leaving does not stop the clinician's panel.
    offParticipant();
    await new Promise((r) => setTimeout(r, 50));
    expect(e.requests.some((m) => m.type === "unwatch")).toBe(false);
    const before = seenByClinician.length;
    await until(() => {
      e.advance(0.05);
      return seenByClinician.length > before;
    }, "the clinician's data");
    offClinician();
    await until(() => e.requests.some((m) => m.type === "unwatch"), "the unwatch");
    // The participant window shows; it does not control.
    const r = await participant.stop();
    expect(r).toMatchObject({ ok: false });
    expect(r.message).toMatch(/only shows/);
    expect(e.requests.some((m) => m.type === "stop")).toBe(false);
  });

  test("a participant window that closes gives its watches back; one opened first greets later", async () => {
    const e = engine();
    const clinician = new EngineClient(e.connection);
    await until(() => clinician.connected, "hello");
    await clinician.load("p.yaml", PIPELINE);
    // The participant window is there before the clinician's page lends its engine.
    const early = relayConnection(openChannel("relay-c"));
    const participant = new EngineClient(early);
    participant.watch("C", "out", () => {});
    const stop = startParticipantRelay(clinician, openChannel("relay-c"));
    closers.push(stop);
    await until(() => participant.connected && participant.graph !== undefined, "a late hello");
    await until(() => e.requests.some((m) => m.type === "watch"), "its watch, sent again");
    participant.close();
    await until(() => e.requests.some((m) => m.type === "unwatch"), "the watch given back");
  });

  test("the participant window hears the clinician's page close, and follows it when it is back", async () => {
    const e = engine();
    const clinician = new EngineClient(e.connection);
    await until(() => clinician.connected, "hello");
    await clinician.load("p.yaml", PIPELINE);
    const link = relayConnection(openChannel("relay-d"));
    const participant = new EngineClient(link);
    closers.push(() => participant.close());
    const said: boolean[] = [];
    link.onLink((up) => said.push(up));
    const stop = startParticipantRelay(clinician, openChannel("relay-d"));
    await until(() => participant.connected, "hello");
    stop(); // the clinician's page closes (or reloads)
    await until(() => said.at(-1) === false, "the relay going down");
    // A new page lends the engine again: the participant greets it and gets the graph.
    const graphs = () => participant.graph;
    participant.graph = undefined;
    closers.push(startParticipantRelay(clinician, openChannel("relay-d")));
    await until(() => said.at(-1) === true && graphs() !== undefined, "the relay back up");
    expect(said).toEqual([true, false, true]);
  });
});
