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

/**
 * TCP: a client (`connect`) or a server for devices that connect to the PC, such as OT
 * Bioelettronica's Muovi (`listen`), with the same socket handle. Bytes arrive as the network
 * delivers them: chunk boundaries mean nothing, so protocols keep their own framing across chunks.
 */
export interface TcpSocketHandle {
  /** Sends bytes (copied; a string goes as ASCII/UTF-8); false, nothing sent, when not open. */
  write(data: Uint8Array | string): boolean;
  /**
   * Closes after what was written has gone out (a last command reaches the peer); no callback
   * follows, not even `onClose`. Idempotent.
   */
  close(): void;
}

export interface TcpCallbacks {
  /** The connection is open (local and remote addresses). */
  onConnect?(local: Endpoint, remote: Endpoint): void;
  /** Bytes received; `data` is valid during the call only (copy what you keep). */
  onData(data: Uint8Array): void;
  /**
   * Exactly once per connection unless `close()` came first: the connect failed (`wasOpen`
   * false: refused, timed out, host not found) or the open connection ended (closed by the peer,
   * reset, an error); `reason` is one line saying what happened and what to check. A connection
   * is never reopened: the caller connects again.
   */
  onClose(reason: string, wasOpen: boolean): void;
}

export interface TcpConnectOptions {
  /** A connect not answered within this many ms fails (default 5000). */
  timeoutMs?: number;
}

/** What a server tells its owner (`TcpBridge.listen`). */
export interface TcpListenCallbacks {
  /** Listening at `local` (the port chosen when 0 was asked). */
  onListening?(local: Endpoint): void;
  /**
   * A peer connected (one at a time: a new peer replaces the current one, whose `onClose` says
   * so, as a device that reconnects after a dropped link may leave a dead connection behind).
   * Returns the callbacks of this connection; `peer` writes to it and closes it.
   */
  onPeer(remote: Endpoint, peer: TcpSocketHandle): Omit<TcpCallbacks, "onConnect">;
  /** The server could not listen (port taken, address not here) or failed: one line; it is closed. */
  onError(reason: string): void;
}

/** A listening server: `close` stops listening and closes the current peer (no callback follows). */
export interface TcpServerHandle {
  close(): void;
}

export interface TcpBridge {
  connect(to: Endpoint, callbacks: TcpCallbacks, options?: TcpConnectOptions): TcpSocketHandle;
  /** Listens at `at` (host "0.0.0.0" for every interface; port 0: any free one). */
  listen?(at: Endpoint, callbacks: TcpListenCallbacks): TcpServerHandle;
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
  /** Closes the port once what was written has gone out (see `closed`). */
  close(): void;
  /** Resolves when the port is closed after `close` (its last writes drained, or given up on). */
  closed?(): Promise<void>;
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

/** One rosbridge connection's state, as `RosConnectOptions.onState` reports it. */
export type RosConnectionState = "connecting" | "connected" | "disconnected";

export interface RosConnectOptions {
  /** The rosbridge server, `ws://host:port` or `wss://host:port`. */
  url: string;
  /**
   * `connecting` first, `connected` once the WebSocket is open, then `disconnected` exactly once
   * (with the reason: refused, closed by the server, a bad URL) — after a failed attempt as well
   * as after a lost connection. A connection is never reopened: the caller connects again.
   */
  onState: (state: RosConnectionState, message?: string) => void;
  /** Status and error messages the server sends (rosbridge `status` op), and protocol errors. */
  onNotice?: (message: string) => void;
}

export interface RosPublisher {
  /** Sends one message (rosbridge `publish`); false (and nothing sent) when not connected. */
  publish(msg: object): boolean;
  /** Stops publishing (rosbridge `unadvertise`). */
  unadvertise(): void;
}

export interface RosSubscription {
  /** Stops the callbacks (rosbridge `unsubscribe`). */
  unsubscribe(): void;
}

export interface RosConnection {
  /** Announces this client as a publisher of `topic` (rosbridge `advertise`). */
  advertise(options: {
    topic: string;
    type: string;
    latch?: boolean;
    queueSize?: number;
  }): RosPublisher;
  /**
   * Asks for the messages of `topic` (rosbridge `subscribe`); each arrives as the parsed `msg`
   * object. `throttleMs` and `queueLength` are rosbridge's `throttle_rate` and `queue_length`.
   */
  subscribe(options: {
    topic: string;
    type: string;
    throttleMs?: number;
    queueLength?: number;
    onMessage: (msg: unknown) => void;
  }): RosSubscription;
  /** Closes the WebSocket; no callbacks follow (not even `disconnected`). */
  close(): void;
}

/** ROS through a rosbridge server (the rosbridge v2 JSON protocol over a WebSocket). */
export interface RosBridge {
  connect(options: RosConnectOptions): RosConnection;
}

/**
 * Bluetooth LE (MOSAIC's BluetoothLEManager). UUIDs are written as noble writes them: 32
 * lower-case hex digits without dashes for 128-bit UUIDs, 4 for 16-bit ones; bridges accept dashes
 * and either case, and report them in that form. Addresses are "aa:bb:cc:dd:ee:ff" (lower case)
 * where the OS reveals them, else the OS's id of the device (macOS).
 */
export type BleAdapterState =
  | "unknown"
  | "resetting"
  | "unsupported"
  | "unauthorized"
  | "poweredOff"
  | "poweredOn"
  /** No adapter, or no BLE driver could be loaded: the message says why. */
  | "unavailable";

export interface BlePeripheral {
  address: string;
  name?: string;
  rssi?: number;
  /** Service UUIDs in its advertisement. */
  services: string[];
}

export interface BleCharacteristic {
  service: string;
  uuid: string;
  /** "read", "write", "writeWithoutResponse", "notify", "indicate", … */
  properties: string[];
}

export interface BleConnection {
  readonly address: string;
  /** The characteristics of these services (all services when the list is empty). */
  discover(services: readonly string[]): Promise<BleCharacteristic[]>;
  /** Enables notifications (or indications); `onData` gets every value until disconnect. */
  subscribe(
    service: string,
    characteristic: string,
    onData: (data: Uint8Array) => void,
  ): Promise<void>;
  write(
    service: string,
    characteristic: string,
    data: Uint8Array,
    withoutResponse?: boolean,
  ): Promise<void>;
  /** Disconnects (idempotent); `onDisconnect` of `connect` is not called for this one. */
  disconnect(): void;
}

export interface BleBridge {
  /** Calls `onChange` with the adapter's state now and on every change, until `close`. */
  watchState(onChange: (state: BleAdapterState, message?: string) => void): { close(): void };
  /**
   * Scans for peripherals advertising one of `services` (any when empty) until `stop`; each
   * peripheral is reported once per scan. Several scans may run at once.
   */
  scan(options: {
    services: readonly string[];
    onFound: (peripheral: BlePeripheral) => void;
    onError: (message: string) => void;
  }): { stop(): void };
  /**
   * Connects to a peripheral found by a scan (by its address). `onDisconnect` reports a link
   * lost later (out of range, switched off), never a `disconnect()` asked for.
   */
  connect(address: string, onDisconnect: (reason: string) => void): Promise<BleConnection>;
}

/**
 * The Python sidecar (issue 7): one process per Python block, started by `load`, that runs the
 * block's user function on every frame it is given (native-bridges/python.ts and
 * native-bridges/python/, protocol in docs/protocols.md). Calls are asynchronous: `call` returns
 * at once and the result arrives later on the worker's event loop, in call order.
 */
export interface PythonLoadOptions {
  /** A `.py` file (absolute, or relative to `cwd`) or an importable module name. */
  module: string;
  /** The function called for every frame: `fn(x)` or `fn(x, state)`. */
  function: string;
  /** Called once as `init(params) -> state` at load and after `reset`. */
  init?: string;
  /** Passed to `init` (plain JSON). */
  params: Record<string, unknown>;
  /** Shape of `x` (the input events' shape). */
  inputShape: { rows: number; cols: number };
  /** When given, the load fails unless the function's result has as many values. */
  outputShape?: { rows: number; cols: number };
  /** Working directory of the process (the pipeline's folder; its modules are importable). */
  cwd?: string;
  /** Who asks (for messages): "block 'Net'". */
  label: string;
  /**
   * A call not answered after this many ms is given up: the process is killed (the call and
   * those behind it fail, the first with kind `timeout`) and restarted (default: none).
   */
  hardLimitMs?: number;
  /** While a call has been running longer than this (ms), `onLate` reports it (every ~50 ms). */
  lateAfterMs?: number;
  /** The process's data memory limit in MB (RLIMIT_DATA; 0 or absent: none). */
  memoryLimitMb?: number;
  /** A result (`values` is valid during the callback only) with the Python-side compute time. */
  onResult(id: number, values: Float64Array, computeUs: number): void;
  /** An exception in the user function (with its traceback), or a call lost to a crash. */
  onError(id: number, error: PythonCallError): void;
  /** The oldest call in flight (`id`) has been running `runningMs` (beyond `lateAfterMs`). */
  onLate?(id: number, runningMs: number): void;
  /** Process life: `restarting` after a crash (with the reason), `ready` when loaded again. */
  onStatus(state: PythonSidecarState, message?: string): void;
  /** Lines the user code printed (stdout and stderr of the process). */
  onOutput?(line: string): void;
}

export type PythonSidecarState = "ready" | "restarting" | "failed" | "closed";

export interface PythonCallError {
  message: string;
  traceback: string;
  /**
   * `call` (an exception), `memory` (a MemoryError), `shape` (a result of another size), `crash`
   * (the process died), `timeout` (the call passed the hard limit; the process was killed).
   */
  kind: string;
}

export interface PythonSidecar {
  /** The output shape found by the probe call at load. */
  readonly outputShape: { rows: number; cols: number };
  /** The process id of the Python interpreter (changes after a restart). */
  readonly pid: number | undefined;
  /** Versions the sidecar reported ("Python 3.11.7, NumPy 2.4.6"). */
  readonly version: string;
  /** True while a process is loaded and accepting calls. */
  readonly ready: boolean;
  /** Sends one input (as many values as the input shape); returns the call id, or -1 when not ready. */
  call(values: Float64Array): number;
  /** Calls `init` again (a fresh state); calls already sent complete first. */
  reset(): void;
  /** Stops the process (shutdown message, then a signal if it does not exit). */
  close(): void;
}

export interface PythonBridge {
  /**
   * Starts a sidecar process and loads the module; rejects with an `Error` whose message says what
   * is wrong (missing module, syntax error with file and line, wrong return shape, an exception in
   * `init`), naming no block (the caller adds that).
   */
  load(options: PythonLoadOptions): Promise<PythonSidecar>;
}

/**
 * Lab Streaming Layer (liblsl through an FFI; native-bridges/lsl.ts). Times are LSL's clock
 * (`localClock`, seconds of a monotonic clock shared by the processes of one machine); blocks map
 * them onto the pipeline clock. Every method may throw an `Error` whose message says what is
 * wrong (the library not found, with where it was looked for; a bad predicate): blocks catch it
 * and show it in their status.
 */
export type LslFormat = "float32" | "double64" | "int32" | "int16" | "string";

/** What a stream says about itself (an outlet's declaration, or a stream found by a resolver). */
export interface LslStreamInfo {
  name: string;
  type: string;
  channels: number;
  /** Nominal sampling rate, Hz; 0 for an irregular stream (markers). */
  rate: number;
  /** Formats this bridge does not handle (int8, int64) read as `other`. */
  format: LslFormat | "other";
  sourceId: string;
  /** Channel labels (outlets: written into the stream's description). */
  labels?: readonly string[];
  /** Where the stream was found (resolved streams only). */
  hostname?: string;
  uid?: string;
}

export interface LslOutletHandle {
  /**
   * Pushes `n` samples as one chunk: `values` row-major (`n * channels`, already in range for an
   * integer format), `timestamps[i]` on LSL's clock. Numeric formats only.
   */
  push(values: Float64Array, n: number, timestamps: Float64Array): void;
  /** Pushes one chunk of string samples (`values.length / channels` samples). */
  pushStrings(values: readonly string[], timestamps: Float64Array): void;
  /** True while at least one inlet is connected. */
  haveConsumers(): boolean;
  close(): void;
}

export interface LslInletHandle {
  /**
   * Pulls what is buffered (never waits), at most `max` samples, into `values` (row-major) and
   * `timestamps` (the sender's clock); returns how many, or -1 when the stream is lost and cannot
   * be recovered (then close this inlet and resolve again).
   */
  pull(values: Float64Array, timestamps: Float64Array, max: number): number;
  /** As `pull` for a string stream: the strings of the samples pulled, in order. */
  pullStrings(into: string[], timestamps: Float64Array, max: number): number;
  /**
   * The latest clock offset: add it to a sender timestamp to get this machine's LSL time, with
   * its uncertainty (the round trip, s); undefined until liblsl has a first estimate (it asks in
   * the background; never waits).
   */
  timeCorrection(): { offset: number; uncertainty: number } | undefined;
  close(): void;
}

/** A continuous resolver: the streams matching a predicate, kept current in the background. */
export interface LslResolverHandle {
  /** The streams seen now (never waits). */
  results(): LslStreamInfo[];
  /** Opens an inlet on a stream of `results()` (by uid); `bufferS`: seconds liblsl may buffer. */
  openInlet(stream: LslStreamInfo, options: { bufferS: number; recover: boolean }): LslInletHandle;
  close(): void;
}

export interface LslBridge {
  /** "liblsl 1.18 (/path/to/liblsl.so)". */
  readonly version: string;
  /** LSL's clock now, s. */
  localClock(): number;
  createOutlet(info: LslStreamInfo, options: { bufferS: number }): LslOutletHandle;
  /** Starts resolving streams that match an XPath predicate such as `name='EMG' and type='EMG'`. */
  resolve(predicate: string): LslResolverHandle;
}

/** Every bridge the host could provide (all optional). Issue 6 fills these in. */
export interface IoBridges {
  udp?: UdpBridge;
  tcp?: TcpBridge;
  serial?: SerialBridge;
  ble?: BleBridge;
  ros?: RosBridge;
  python?: PythonBridge;
  /** Lab Streaming Layer (liblsl); absent in the browser build. */
  lsl?: LslBridge;
  /** Bluetooth LE and ROS bridges are declared by their blocks' issue (6). */
  [name: string]: unknown;
}
