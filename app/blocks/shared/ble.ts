/**
 * What the Bluetooth LE device links (the Myo block's, io/myo-run.ts; the NilsPod block's,
 * devices/nilspod-link.ts) share: the adapter-state messages, the registry of claimed addresses,
 * and the connection attempt with its generation check.
 */
import type { BleAdapterState, BleBridge, BleConnection } from "../../engine";

/** The status text for an adapter state that is not "poweredOn" (when the bridge gave none). */
export const ADAPTER_TEXT: Record<Exclude<BleAdapterState, "poweredOn">, string> = {
  unknown: "waiting for the Bluetooth adapter…",
  resetting: "the Bluetooth adapter is resetting…",
  unsupported: "the Bluetooth adapter does not support Bluetooth LE",
  unauthorized: "not allowed to use the Bluetooth adapter",
  poweredOff: "Bluetooth is off (switch it on; on Linux: bluetoothctl power on)",
  unavailable: "no Bluetooth adapter",
};

/** A Bluetooth address as a key: without ':' and '-', lower case. */
export const addressKey = (a: string): string => a.replace(/[:-]/g, "").toLowerCase();

/**
 * Addresses (as `addressKey`s) in use by a device block, per bridge: a block without Address
 * skips them. One registry shared by all block types (the Myo and the NilsPod blocks): an
 * address is one physical device, whichever block claimed it.
 */
const claimed = new WeakMap<BleBridge, Set<string>>();
export function claimsOf(b: BleBridge): Set<string> {
  let s = claimed.get(b);
  if (!s) claimed.set(b, (s = new Set()));
  return s;
}

export const errorText = (e: unknown): string => (e as Error)?.message ?? String(e);

/** One connection attempt of a link, as `connectAttempt` sees it. */
export interface BleAttempt {
  /** Called by the bridge when the connection is lost (the bridge's `onLost`). */
  onLost(reason: string): void;
  /** Whether the attempt is still the link's current one (its generation did not change). */
  current(): boolean;
  /** The link's failure path, called (only while current) with "connection failed: …". */
  fail(reason: string): void;
  /** Called with the connection when it is established and the attempt still current. */
  connected(c: BleConnection): Promise<void>;
}

/**
 * Connects to `address`. A failed connection is reported through `a.fail` while the attempt is
 * current; a connection that arrives after the attempt went stale is disconnected; else
 * `a.connected` takes it over (called synchronously after the connection arrives).
 */
export async function connectAttempt(
  bridge: BleBridge,
  address: string,
  a: BleAttempt,
): Promise<void> {
  let c: BleConnection;
  try {
    c = await bridge.connect(address, (reason) => a.onLost(reason));
  } catch (e) {
    if (a.current()) a.fail(`connection failed: ${errorText(e)}`);
    return;
  }
  if (!a.current()) {
    c.disconnect();
    return;
  }
  await a.connected(c);
}
