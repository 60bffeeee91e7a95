/**
 * The TCP bridge for Node (node:net), given to blocks as `ctx.io.tcp` by the host's engine
 * workers (app/engine/io.ts). A client connection: `connect` returns a handle at once; the
 * connection opens (`onConnect`), delivers bytes as they come (`onData`, chunk boundaries mean
 * nothing) and ends exactly once with one line saying why (`onClose`), unless the caller closed it
 * first. Nagle is off (a device's small commands leave at once). `close` ends the connection after
 * what was written has gone out (a last STOP reaches the device) and destroys it after
 * `CLOSE_GRACE_MS` if the peer keeps it open.
 *
 * Errors never throw into the block: they come back through `onClose` (connection refused, host
 * not found, timed out, reset by the peer).
 *
 * A server (`listen`) accepts one peer at a time, with the same handle and callbacks; a new peer
 * replaces the current one (a device reconnecting after a dropped Wi-Fi link leaves a dead
 * connection behind that would otherwise hold the place).
 */
import { connect as netConnect, createServer, isIP, type Server, type Socket } from "node:net";
import type {
  Endpoint,
  TcpBridge,
  TcpCallbacks,
  TcpConnectOptions,
  TcpListenCallbacks,
  TcpServerHandle,
  TcpSocketHandle,
} from "../app/engine/io";

/** How long a closed connection may take to flush its last writes before it is destroyed, ms. */
export const CLOSE_GRACE_MS = 1000;
/** Default connect timeout, ms. */
export const CONNECT_TIMEOUT_MS = 5000;

export const showEndpoint = (e: Endpoint): string =>
  isIP(e.host) === 6 ? `[${e.host}]:${e.port}` : `${e.host}:${e.port}`;

/** One line for a failed or ended connection: the cause in words, then the system code. */
export function describeTcpError(err: unknown, at: Endpoint, wasOpen: boolean): string {
  const e = err as NodeJS.ErrnoException;
  const code = typeof e?.code === "string" ? e.code : "";
  const where = showEndpoint(at);
  switch (code) {
    case "ECONNREFUSED":
      return `nothing is listening at ${where} (ECONNREFUSED): start the server there, or check Host and Port`;
    case "ENOTFOUND":
    case "EAI_AGAIN":
    case "EAI_NONAME":
      return `cannot resolve host '${at.host}' (${code}): check the Host name or use an IP address`;
    case "ETIMEDOUT":
      return `no answer from ${where} (ETIMEDOUT): check the network, the Host and any firewall`;
    case "ENETUNREACH":
    case "EHOSTUNREACH":
      return `${where} is unreachable (${code}): check the network and the Host`;
    case "ECONNRESET":
      return `${where} reset the connection (ECONNRESET)`;
    case "EPIPE":
      return `${where} closed the connection while data was being sent (EPIPE)`;
    case "EADDRNOTAVAIL":
      return `cannot connect to ${where} (EADDRNOTAVAIL): the address is not usable from this machine`;
    default: {
      const msg = e instanceof Error ? e.message : String(err);
      return `${wasOpen ? "connection to" : "connect to"} ${where} failed: ${msg}`;
    }
  }
}

class NodeTcpSocket implements TcpSocketHandle {
  private readonly socket: Socket;
  private open = false;
  private closed = false;
  private ended = false;

  constructor(
    private readonly to: Endpoint,
    private readonly cb: TcpCallbacks,
    options: TcpConnectOptions,
    accepted?: Socket,
  ) {
    const timeoutMs = options.timeoutMs ?? CONNECT_TIMEOUT_MS;
    this.socket = accepted ?? netConnect({ host: to.host, port: to.port });
    this.open = accepted !== undefined;
    this.socket.setNoDelay(true);
    if (accepted) this.listenTo(to);
    else this.connectTo(to, timeoutMs);
  }

  private connectTo(to: Endpoint, timeoutMs: number): void {
    this.socket.setTimeout(timeoutMs);
    this.socket.on("timeout", () => {
      if (this.open) return;
      this.end(
        `no answer from ${showEndpoint(to)} within ${timeoutMs / 1000} s (connect timed out): check the Host, the network and any firewall`,
      );
    });
    this.socket.on("connect", () => {
      if (this.closed) return;
      this.open = true;
      this.socket.setTimeout(0);
      const s = this.socket;
      this.cb.onConnect?.(
        { host: s.localAddress ?? "", port: s.localPort ?? 0 },
        { host: s.remoteAddress ?? to.host, port: s.remotePort ?? to.port },
      );
    });
    this.listenTo(to);
  }

  private listenTo(to: Endpoint): void {
    this.socket.on("data", (buf: Buffer) => {
      if (this.closed) return;
      this.cb.onData(new Uint8Array(buf.buffer, buf.byteOffset, buf.length));
    });
    this.socket.on("error", (err) => {
      this.end(describeTcpError(err, to, this.open));
    });
    this.socket.on("end", () => {
      // The peer closed its side: so do we (no half-open connections).
      this.end(`${showEndpoint(to)} closed the connection`);
    });
    this.socket.on("close", () => {
      this.end(`the connection to ${showEndpoint(to)} closed`);
    });
  }

  /** Reports the end once (unless the caller closed first) and releases the socket. */
  private end(reason: string): void {
    if (this.ended) return;
    this.ended = true;
    const wasOpen = this.open;
    this.open = false;
    this.socket.destroy();
    if (!this.closed) {
      this.closed = true;
      this.cb.onClose(reason, wasOpen);
    }
  }

  /** The peer's address. */
  get remote(): Endpoint {
    return this.to;
  }

  /** Ends the connection now, reporting `reason` through onClose (a server's replaced peer). */
  drop(reason: string): void {
    this.end(reason);
  }

  write(data: Uint8Array | string): boolean {
    if (this.closed || !this.open) return false;
    // A copy: callers reuse their buffers.
    this.socket.write(typeof data === "string" ? data : Buffer.from(data));
    return true;
  }

  close(): void {
    if (this.closed) return;
    this.closed = true;
    if (!this.open) {
      this.ended = true;
      this.socket.destroy();
      return;
    }
    this.open = false;
    this.socket.end();
    const timer = setTimeout(() => this.socket.destroy(), CLOSE_GRACE_MS);
    timer.unref();
    this.socket.once("close", () => clearTimeout(timer));
  }
}

/** One line for a server that cannot listen. */
export function describeListenError(err: unknown, at: Endpoint): string {
  const e = err as NodeJS.ErrnoException;
  const where = showEndpoint(at);
  switch (e?.code) {
    case "EADDRINUSE":
      return `cannot listen at ${where}: the port is in use (EADDRINUSE) — another program (or another block) listens there; choose another Port or stop it`;
    case "EACCES":
      return `cannot listen at ${where}: permission denied (EACCES) — ports below 1024 need privileges; choose a Port of 1024 or more`;
    case "EADDRNOTAVAIL":
      return `cannot listen at ${where}: the address is not one of this machine's (EADDRNOTAVAIL)`;
    default:
      return `cannot listen at ${where}: ${e instanceof Error ? e.message : String(err)}`;
  }
}

/** A server that accepts one peer at a time (see the file comment). */
class NodeTcpServer implements TcpServerHandle {
  private readonly server: Server;
  private peer: NodeTcpSocket | undefined;
  private closed = false;

  constructor(
    private readonly at: Endpoint,
    private readonly cb: TcpListenCallbacks,
  ) {
    this.server = createServer((s) => this.accept(s));
    this.server.on("error", (err) => {
      if (this.closed) return;
      this.close();
      this.cb.onError(describeListenError(err, at));
    });
    this.server.listen({ host: at.host, port: at.port, exclusive: true }, () => {
      if (this.closed) return;
      const a = this.server.address();
      const port = a !== null && typeof a === "object" ? a.port : at.port;
      this.cb.onListening?.({ host: at.host, port });
    });
  }

  private accept(socket: Socket): void {
    if (this.closed) {
      socket.destroy();
      return;
    }
    const remote = { host: socket.remoteAddress ?? "", port: socket.remotePort ?? 0 };
    const old = this.peer;
    // The owner's callbacks for this peer, known once onPeer has returned (events come later).
    const inner: { cb?: Omit<TcpCallbacks, "onConnect"> } = {};
    const handle = new NodeTcpSocket(
      remote,
      {
        onData: (d) => inner.cb?.onData(d),
        onClose: (reason, wasOpen) => {
          if (this.peer === handle) this.peer = undefined;
          inner.cb?.onClose(reason, wasOpen);
        },
      },
      {},
      socket,
    );
    this.peer = handle;
    old?.drop(
      `${showEndpoint(old.remote)} was replaced by a new connection from ${showEndpoint(remote)}`,
    );
    inner.cb = this.cb.onPeer(remote, handle);
  }

  close(): void {
    if (this.closed) return;
    this.closed = true;
    this.peer?.close();
    this.peer = undefined;
    this.server.close();
  }
}

/** The TCP bridge the Node host gives its engine workers. */
export function nodeTcpBridge(): TcpBridge {
  return {
    connect(to: Endpoint, callbacks: TcpCallbacks, options: TcpConnectOptions = {}) {
      return new NodeTcpSocket(to, callbacks, options);
    },
    listen(at: Endpoint, callbacks: TcpListenCallbacks) {
      return new NodeTcpServer(at, callbacks);
    },
  };
}
