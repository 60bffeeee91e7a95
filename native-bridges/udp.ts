/**
 * The UDP bridge for Node (node:dgram), given to blocks as `ctx.io.udp` by the host's engine
 * workers (app/engine/io.ts). Receivers bind; senders bind an ephemeral port and connect to their
 * destination once it is resolved, so that each `send` leaves synchronously (no per-datagram
 * address lookup, nothing waits for the event loop, which a busy worker turns only now and then).
 * Datagrams sent before the connection is made (the first milliseconds) wait in a short queue.
 * `send` copies the datagram: blocks reuse their buffers.
 *
 * Errors never throw into the block: they come back through `onError` as one line that says what
 * went wrong and what to do (port in use, address not on this machine, host not found, nothing
 * listening at the destination).
 *
 * A sender (a socket opened with `remote`) loses no datagram silently: **every datagram it does not
 * send is one `onError` call**, whatever the cause — the host name does not resolve (each datagram
 * queued meanwhile, and every later one until a new lookup, retried at most every
 * RESOLVE_RETRY_S, succeeds), the queue overflows while connecting, or the send fails later
 * (ECONNREFUSED when nothing listens, EHOSTUNREACH…: every send carries a completion callback,
 * because Node drops a failed send without one silently). So a block counts its `onError` calls
 * as datagrams not sent.
 */
import { createSocket, type Socket } from "node:dgram";
import { lookup } from "node:dns";
import { isIP } from "node:net";
import type { Endpoint, UdpBridge, UdpOpenOptions, UdpSocketHandle } from "../app/engine/io";

const show = (e: Endpoint): string =>
  e.host.includes(":") ? `[${e.host}]:${e.port}` : `${e.host}:${e.port}`;

/** One line for a socket error: the cause in words, then the system code. */
export function describeUdpError(
  err: unknown,
  op: "bind" | "send" | "resolve",
  at: Endpoint,
): string {
  const e = err as NodeJS.ErrnoException;
  const code = typeof e?.code === "string" ? e.code : "";
  const where = show(at);
  switch (code) {
    case "EADDRINUSE":
      return `port ${at.port} is already in use on ${at.host} (EADDRINUSE): another program or block is listening there; choose another Port or stop the other one`;
    case "EACCES":
      return `no permission to use port ${at.port} on ${at.host} (EACCES): ports below 1024 need administrator rights; choose a port from 1024`;
    case "EADDRNOTAVAIL":
      return `${at.host} is not an address of this machine (EADDRNOTAVAIL): use 127.0.0.1, 0.0.0.0 or one of its interface addresses`;
    case "ENOTFOUND":
    case "EAI_AGAIN":
    case "EAI_NONAME":
      return `cannot resolve host '${at.host}' (${code}): check the Host name or use an IP address`;
    case "ECONNREFUSED":
      return `nothing is listening at ${where} (ECONNREFUSED): start the receiving program, or check Host and Port`;
    case "ENETUNREACH":
    case "EHOSTUNREACH":
      return `${where} is unreachable (${code}): check the network and the Host`;
    case "EMSGSIZE":
      return `datagram too large for ${where} (EMSGSIZE)`;
    default: {
      const msg = e instanceof Error ? e.message : String(err);
      return `${op} ${where} failed: ${msg}`;
    }
  }
}

/** Datagrams kept while the sender connects (resolving a host name may take a while). */
export const MAX_PENDING = 256;
/** After a failed lookup or connect, the next datagram tries again at most this often, s. */
export const RESOLVE_RETRY_S = 5;

function familyOf(host: string): "udp4" | "udp6" {
  return isIP(host) === 6 ? "udp6" : "udp4";
}

class NodeUdpSocket implements UdpSocketHandle {
  private readonly socket: Socket;
  private closed = false;
  private bound = false;
  /** Connected to `remote` (sends go without an address). */
  private connected = false;
  /** Why the last lookup or connect failed (datagrams are then dropped, one error each). */
  private failure: string | undefined;
  private failedAt = 0;
  private readonly pending: Buffer[] = [];

  constructor(private readonly o: UdpOpenOptions) {
    const host = o.bind?.host ?? o.remote?.host ?? "127.0.0.1";
    this.socket = createSocket({ type: familyOf(host), reuseAddr: false });
    this.socket.on("error", (err) => {
      if (this.closed) return;
      const bindFailed = o.bind !== undefined && !this.bound;
      this.o.onError(
        describeUdpError(
          err,
          bindFailed ? "bind" : "send",
          (bindFailed ? o.bind : o.remote) ?? { host, port: 0 },
        ),
      );
    });
    if (o.onMessage) {
      const onMessage = o.onMessage;
      this.socket.on("message", (msg, rinfo) => {
        if (this.closed) return;
        onMessage(new Uint8Array(msg.buffer, msg.byteOffset, msg.length), {
          host: rinfo.address,
          port: rinfo.port,
        });
      });
    }
    if (o.bind) {
      this.socket.bind({ port: o.bind.port, address: o.bind.host, exclusive: true }, () => {
        this.bound = true;
        if (!this.closed) this.ready();
      });
    } else if (o.remote) {
      this.connect(o.remote);
    }
  }

  private ready(): void {
    const a = this.socket.address();
    this.o.onReady?.({ host: a.address, port: a.port });
  }

  /** One `onError` per datagram not sent. */
  private lost(count: number, message: string): void {
    for (let i = 0; i < count && !this.closed; i++) this.o.onError(message);
  }

  /** The lookup or connect failed: every datagram waiting is lost, and later ones until a retry. */
  private fail(message: string): void {
    this.failure = message;
    this.failedAt = performance.now();
    const queued = this.pending.splice(0);
    this.lost(queued.length, message);
  }

  /** Resolves the destination once, then connects (sends before that wait in `pending`). */
  private connect(remote: Endpoint): void {
    this.failure = undefined;
    const go = (ip: string): void => {
      if (this.closed) return;
      try {
        this.socket.connect(remote.port, ip, (err?: Error) => {
          if (this.closed) return;
          if (err) {
            this.fail(describeUdpError(err, "send", remote));
            return;
          }
          this.connected = true;
          this.ready();
          const queued = this.pending.splice(0);
          for (const b of queued) this.sendNow(b);
        });
      } catch (e) {
        this.fail(describeUdpError(e, "send", remote));
      }
    };
    if (isIP(remote.host) !== 0) {
      go(remote.host);
      return;
    }
    lookup(remote.host, { family: 4 }, (err, address) => {
      if (this.closed) return;
      if (err) this.fail(describeUdpError(err, "resolve", remote));
      else go(address);
    });
  }

  /** Completion of every send: a failed one is a datagram lost (Node reports it nowhere else). */
  private readonly afterSend = (err: Error | null): void => {
    if (err && !this.closed) {
      this.o.onError(describeUdpError(err, "send", this.o.remote ?? { host: "?", port: 0 }));
    }
  };

  /**
   * Sends with a completion callback: libuv still writes the datagram at once when nothing waits
   * before it (the callback only comes later, on the event loop), and a failure reaches
   * `afterSend` instead of vanishing as it does without a callback.
   */
  private sendNow(buf: Buffer, to?: Endpoint): void {
    try {
      if (to) this.socket.send(buf, to.port, to.host, this.afterSend);
      else this.socket.send(buf, this.afterSend);
    } catch (e) {
      this.o.onError(describeUdpError(e, "send", to ?? this.o.remote ?? { host: "?", port: 0 }));
    }
  }

  send(data: Uint8Array, to?: Endpoint): void {
    if (this.closed) return;
    if (to) {
      if (this.connected) this.o.onError("send with an address on a connected socket");
      else this.sendNow(Buffer.from(data), to);
      return;
    }
    if (this.connected) {
      this.sendNow(Buffer.from(data));
      return;
    }
    const remote = this.o.remote;
    if (!remote) {
      this.o.onError("send without a destination (the socket was opened without `remote`)");
      return;
    }
    if (this.failure !== undefined) {
      if (performance.now() - this.failedAt < RESOLVE_RETRY_S * 1000) {
        this.o.onError(this.failure);
        return;
      }
      this.connect(remote); // try again; this datagram waits for the outcome
    }
    // A copy: the caller reuses `data`.
    if (this.pending.length < MAX_PENDING) this.pending.push(Buffer.from(data));
    else {
      this.o.onError(
        `datagram dropped: more than ${MAX_PENDING} waiting while connecting to ${show(remote)}`,
      );
    }
  }

  close(): void {
    if (this.closed) return;
    const queued = this.pending.splice(0);
    if (queued.length > 0 && this.o.remote) {
      this.lost(queued.length, `not sent: closed while connecting to ${show(this.o.remote)}`);
    }
    this.closed = true;
    try {
      this.socket.close();
    } catch {
      // already closed (e.g. after a failed bind)
    }
  }
}

/** The UDP bridge the Node host gives its engine workers. */
export function nodeUdpBridge(): UdpBridge {
  return {
    open(options: UdpOpenOptions): UdpSocketHandle {
      return new NodeUdpSocket(options);
    },
  };
}
