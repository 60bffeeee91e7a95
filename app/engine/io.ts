/**
 * Device and network I/O as blocks see it. The engine runs in browsers too, so blocks never
 * import sockets or serial ports: the host passes implementations of these interfaces
 * (native-bridges/, Node only) through `ctx.io`; where one is missing (the browser build), the
 * block says so in its status and nothing else breaks. Callbacks arrive on the worker's event
 * loop; blocks that use them declare `eventLoop: true`.
 */

export interface Endpoint {
  host: string;
  port: number;
}

export interface UdpSocketHandle {
  send(data: Uint8Array, to?: Endpoint): void;
  close(): void;
}

export interface UdpOpenOptions {
  /** Local address to bind (receivers); omitted for a sender (an ephemeral port). */
  bind?: Endpoint;
  /** Default destination of `send`. */
  remote?: Endpoint;
  onMessage?: (data: Uint8Array, from: Endpoint) => void;
  onReady?: (local: Endpoint) => void;
  onError: (message: string) => void;
}

export interface UdpBridge {
  open(options: UdpOpenOptions): UdpSocketHandle;
}

export interface SerialOptions {
  path: string;
  baudRate: number;
  dataBits: 5 | 6 | 7 | 8;
  stopBits: 1 | 1.5 | 2;
  parity: "none" | "even" | "odd" | "mark" | "space";
}

export type SerialStatus = "opening" | "open" | "closed" | "error";

export interface SerialHandle {
  write(data: Uint8Array): void;
  close(): void;
}

export interface SerialBridge {
  /**
   * Opens the port and keeps it open: after a failed open or an unplug the bridge reports
   * `error` (with the reason) and retries every `reconnectMs` (0: never) until `close`.
   */
  open(
    options: SerialOptions & {
      reconnectMs: number;
      onData: (data: Uint8Array) => void;
      onStatus: (status: SerialStatus, message?: string) => void;
    },
  ): SerialHandle;
  list(): Promise<{ path: string; manufacturer?: string }[]>;
}

/** Every bridge the host could provide (all optional). Issue 6 fills these in. */
export interface IoBridges {
  udp?: UdpBridge;
  serial?: SerialBridge;
  /** Bluetooth LE and ROS bridges are declared by their blocks' issue (6). */
  [name: string]: unknown;
}
