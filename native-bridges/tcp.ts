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
 */
import { connect as netConnect, isIP, type Socket } from "node:net";
import type {
  Endpoint,
  TcpBridge,
  TcpCallbacks,
  TcpConnectOptions,
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
  ) {
    const timeoutMs = options.timeoutMs ?? CONNECT_TIMEOUT_MS;
    this.socket = netConnect({ host: to.host, port: to.port });
    this.socket.setNoDelay(true);
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

/** The TCP bridge the Node host gives its engine workers. */
export function nodeTcpBridge(): TcpBridge {
  return {
    connect(to: Endpoint, callbacks: TcpCallbacks, options: TcpConnectOptions = {}) {
      return new NodeTcpSocket(to, callbacks, options);
    },
  };
}
