/**
 * The ROS bridge for Node, given to blocks as `ctx.io.ros` by the host's engine workers
 * (app/engine/io.ts): rosbridge v2 over a WebSocket, through roslib (its `Ros` and `Topic` speak
 * the protocol: advertise, publish, subscribe, unsubscribe, unadvertise, status, fragments).
 *
 * roslib is loaded on the first connection only (a separate chunk of the bundle: workers without
 * a ROS block never parse it), and it gets a transport of ours on the `ws` package instead of its
 * default one, which picks the global `WebSocket` where there is one (Node ≥ 22) and reports
 * failures as bare events. Ours is the same on every Node version, reports why a connection
 * failed (refused, host unknown, HTTP status, handshake timeout) and pings the server, so that a
 * connection that silently died (a robot's Wi-Fi gone) is noticed within seconds.
 *
 * One `connect` is one attempt: it reports `connecting`, `connected`, then `disconnected` once,
 * and never reconnects by itself (the block does, with its backoff). Publishing while not connected
 * returns false: roslib would queue such messages until the next connection, unbounded.
 */
import type { ClientRequest, IncomingMessage } from "node:http";
import type WebSocket from "ws";
import type {
  RosBridge,
  RosConnection,
  RosConnectOptions,
  RosPublisher,
  RosSubscription,
} from "../app/engine/io";

type RoslibModule = typeof import("roslib");
type RosInstance = InstanceType<RoslibModule["Ros"]>;
type TopicInstance = InstanceType<RoslibModule["Topic"]>;
type WsClass = typeof WebSocket;

interface Libs {
  roslib: RoslibModule;
  WebSocket: WsClass;
}

let libs: Promise<Libs> | undefined;
/** roslib and ws, loaded once, on the first connection (separate chunks of the bundle). */
const loadLibs = (): Promise<Libs> =>
  (libs ??= Promise.all([import("roslib"), import("ws")]).then(([roslib, ws]) => ({
    roslib,
    WebSocket: ws.default,
  })));

/** Seconds allowed for the WebSocket handshake; then between pings (a missed pong ends it). */
const HANDSHAKE_MS = 5000;
const PING_MS = 5000;

const CLOSE_CODES: Record<number, string> = {
  1000: "normal closure",
  1001: "going away",
  1002: "protocol error",
  1003: "unsupported data",
  1006: "no close frame: the server stopped or the network failed",
  1008: "policy violation",
  1009: "message too big",
  1011: "server error",
};

/** One line for a failed or lost WebSocket, with the cause in words. */
export function describeRosError(err: unknown, url: string): string {
  const e = err as NodeJS.ErrnoException;
  const code = typeof e?.code === "string" ? e.code : "";
  let where = url;
  try {
    where = new URL(url).host;
  } catch {
    // keep the URL as written
  }
  switch (code) {
    case "ECONNREFUSED":
      return `nothing is listening at ${where} (ECONNREFUSED): start rosbridge (ros2 launch rosbridge_server rosbridge_websocket_launch.xml, or roslaunch rosbridge_server rosbridge_websocket.launch) or check Url`;
    case "ENOTFOUND":
    case "EAI_AGAIN":
      return `cannot resolve the host of ${url} (${code}): check Url`;
    case "ECONNRESET":
      return `the connection to ${where} was reset (ECONNRESET)`;
    case "ETIMEDOUT":
    case "EHOSTUNREACH":
    case "ENETUNREACH":
      return `${where} is unreachable (${code}): check the network and Url`;
    default: {
      const msg = e instanceof Error ? e.message : String(err);
      return msg === "" ? "connection failed" : msg;
    }
  }
}

function closeText(code: number, reason: string): string {
  const known = CLOSE_CODES[code];
  const why = reason !== "" ? `: ${reason}` : known ? ` (${known})` : "";
  return `the connection was closed, code ${code}${why}`;
}

type RosTransport = InstanceType<RoslibModule["AbstractTransport"]>;
type RosTransportClass = new (ws: WebSocket) => RosTransport;

/**
 * roslib's transport on a `ws` socket (like its WsWebSocketTransport, which it does not export),
 * as a subclass of the loaded roslib's AbstractTransport; its `close` calls `shut`.
 */
function wsTransportClass(lib: RoslibModule, shut: (ws: WebSocket) => void): RosTransportClass {
  return class WsTransport extends lib.AbstractTransport {
    constructor(private readonly ws: WebSocket) {
      super();
      ws.on("open", () => this.emit("open", undefined));
      ws.on("close", (code, reason) => this.emit("close", { code, reason: reason.toString() }));
      ws.on("error", (err) => this.emit("error", err));
      ws.on("message", (data, isBinary) => {
        if (!isBinary) this.handleRawMessage(data.toString());
        else {
          const b = Array.isArray(data) ? Buffer.concat(data) : Buffer.from(data as Buffer);
          this.handleRawMessage(b.buffer.slice(b.byteOffset, b.byteOffset + b.byteLength));
        }
      });
    }
    send(message: object): void {
      this.ws.send(JSON.stringify(message));
    }
    close(): void {
      shut(this.ws);
    }
    isConnecting(): boolean {
      return this.ws.readyState === this.ws.CONNECTING;
    }
    isOpen(): boolean {
      return this.ws.readyState === this.ws.OPEN;
    }
    isClosing(): boolean {
      return this.ws.readyState === this.ws.CLOSING;
    }
    isClosed(): boolean {
      return this.ws.readyState === this.ws.CLOSED;
    }
  };
}

class RoslibConnection implements RosConnection {
  private socket: WebSocket | undefined;
  private ros: RosInstance | undefined;
  private lib: RoslibModule | undefined;
  private closed = false;
  private ended = false;
  private open = false;
  private lastError = "";
  /** Whether a pong came since the last ping. */
  private alive = true;
  private pinger: ReturnType<typeof setInterval> | undefined;
  /** Topics wait here while roslib loads. */
  private readonly pending: ((lib: RoslibModule, ros: RosInstance) => void)[] = [];

  constructor(private readonly o: RosConnectOptions) {
    o.onState("connecting");
    loadLibs().then(
      (l) => this.start(l.roslib, l.WebSocket),
      (e: unknown) => this.end(`cannot load roslib: ${describeRosError(e, o.url)}`),
    );
  }

  /** Builds roslib's `Ros` on our transport, follows its events and connects. */
  private start(lib: RoslibModule, WebSocket: WsClass): void {
    if (this.closed || this.ended) return;
    const url = this.o.url;
    const Transport = wsTransportClass(lib, (ws) => this.shut(ws));
    const ros = new lib.Ros({
      transportFactory: (u: string) => Promise.resolve(this.transport(u, WebSocket, Transport)),
    });
    this.ros = ros;
    this.lib = lib;
    ros.on("connection", () => this.onConnection());
    ros.on("error", (e: unknown) => this.onError(e));
    ros.on("close", (e: unknown) => this.onClose(e));
    ros.connect(url).catch((e: unknown) => this.end(describeRosError(e, url)));
    for (const f of this.pending.splice(0)) f(lib, ros);
  }

  /**
   * The transport roslib asks for: a socket to `u` whose HTTP answers (not a WebSocket) and
   * pongs are noted, and whose `status` ops become notices.
   */
  private transport(u: string, WebSocket: WsClass, Transport: RosTransportClass): RosTransport {
    const ws = new WebSocket(u, { handshakeTimeout: HANDSHAKE_MS });
    this.socket = ws;
    ws.on("unexpected-response", (_req: ClientRequest, res: IncomingMessage) => {
      this.lastError = `${u} answered HTTP ${res.statusCode ?? "?"} ${res.statusMessage ?? ""}, not a WebSocket: is this a rosbridge server?`;
      ws.terminate();
    });
    ws.on("pong", () => (this.alive = true));
    const transport = new Transport(ws);
    // Every `status` op, whatever its id (roslib routes them by the id of the op they
    // concern, e.g. one per published message).
    transport.on("message", (m: { op?: unknown }) => {
      if (m.op === "status") this.notice(m);
    });
    return transport;
  }

  /** roslib connected: reports `connected` and starts pinging. */
  private onConnection(): void {
    if (this.closed || this.ended) return;
    this.open = true;
    this.alive = true;
    this.pinger = setInterval(() => this.ping(), PING_MS);
    this.pinger.unref?.();
    this.o.onState("connected");
  }

  /** A socket error: kept for the `disconnected` message, and a notice while connected. */
  private onError(e: unknown): void {
    this.lastError = describeRosError(e, this.o.url);
    if (this.open && !this.closed) this.o.onNotice?.(this.lastError);
  }

  /** The socket closed: ends the connection with the last error, else the close code. */
  private onClose(e: unknown): void {
    const ev = e as { code?: number; reason?: string } | undefined;
    const how =
      this.lastError !== ""
        ? this.lastError
        : closeText(ev?.code ?? 1006, typeof ev?.reason === "string" ? ev.reason : "");
    this.end(this.open ? `connection lost: ${how}` : how);
  }

  /** Pings the open socket; a ping still unanswered at the next one ends the connection. */
  private ping(): void {
    const ws = this.socket;
    if (!ws || ws.readyState !== ws.OPEN) return;
    if (!this.alive) {
      this.lastError = `no answer to a ping for ${PING_MS / 1000} s: the connection is dead`;
      ws.terminate();
      return;
    }
    this.alive = false;
    ws.ping();
  }

  private notice(m: unknown): void {
    if (this.closed) return;
    const s = m as { level?: unknown; msg?: unknown };
    this.o.onNotice?.(`${String(s.level ?? "status")}: ${String(s.msg ?? JSON.stringify(m))}`);
  }

  private end(message: string): void {
    if (this.ended) return;
    this.ended = true;
    this.stopPing();
    if (!this.closed) this.o.onState("disconnected", message);
  }

  private stopPing(): void {
    if (this.pinger) clearInterval(this.pinger);
    this.pinger = undefined;
  }

  /** Closes politely when open (a close frame), at once otherwise. */
  shut(ws: WebSocket): void {
    if (ws.readyState === ws.OPEN) ws.close(1000);
    else if (ws.readyState === ws.CONNECTING) ws.terminate();
  }

  /** Runs `f` once roslib is loaded (at once when it is). */
  private withRos(f: (lib: RoslibModule, ros: RosInstance) => void): void {
    if (this.closed) return;
    if (this.ros && this.lib) f(this.lib, this.ros);
    else this.pending.push(f);
  }

  advertise(options: {
    topic: string;
    type: string;
    latch?: boolean;
    queueSize?: number;
  }): RosPublisher {
    let topic: TopicInstance | undefined;
    let gone = false;
    this.withRos((lib, ros) => {
      if (gone) return;
      topic = new lib.Topic({
        ros,
        name: options.topic,
        messageType: options.type,
        latch: options.latch ?? false,
        queue_size: options.queueSize ?? 100,
        reconnect_on_close: false,
      });
      topic.advertise();
    });
    return {
      publish: (msg: object): boolean => {
        const ros = this.ros;
        if (!topic || !ros || this.closed || !ros.isConnected) return false;
        topic.publish(msg);
        return true;
      },
      unadvertise: () => {
        gone = true;
        if (topic && this.ros?.isConnected) topic.unadvertise();
      },
    };
  }

  subscribe(options: {
    topic: string;
    type: string;
    throttleMs?: number;
    queueLength?: number;
    onMessage: (msg: unknown) => void;
  }): RosSubscription {
    let topic: TopicInstance | undefined;
    let gone = false;
    this.withRos((lib, ros) => {
      if (gone) return;
      topic = new lib.Topic({
        ros,
        name: options.topic,
        messageType: options.type,
        throttle_rate: options.throttleMs ?? 0,
        queue_length: options.queueLength ?? 0,
        reconnect_on_close: false,
      });
      topic.subscribe((m: unknown) => {
        if (!this.closed && !gone) options.onMessage(m);
      });
    });
    return {
      unsubscribe: () => {
        gone = true;
        if (topic && this.ros?.isConnected) topic.unsubscribe();
      },
    };
  }

  close(): void {
    if (this.closed) return;
    this.closed = true;
    this.stopPing();
    this.pending.length = 0;
    const ws = this.socket;
    if (ws) this.shut(ws);
  }
}

/** The ROS bridge the Node host gives its engine workers. */
export function nodeRosBridge(): RosBridge {
  return {
    connect(options: RosConnectOptions): RosConnection {
      return new RoslibConnection(options);
    },
  };
}
