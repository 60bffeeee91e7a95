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
const MAX_PENDING = 256;

function familyOf(host: string): "udp4" | "udp6" {
  return isIP(host) === 6 ? "udp6" : "udp4";
}

class NodeUdpSocket implements UdpSocketHandle {
  private readonly socket: Socket;
  private closed = false;
  /** Connected to `remote` (sends go without an address). */
  private connected = false;

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

  private bound = false;

  private ready(): void {
    const a = this.socket.address();
    this.o.onReady?.({ host: a.address, port: a.port });
  }

  /** Resolves the destination once, then connects (sends before that carry the address). */
  private connect(remote: Endpoint): void {
    const go = (ip: string): void => {
      if (this.closed) return;
      this.socket.connect(remote.port, ip, (err?: Error) => {
        if (this.closed) return;
        if (err) {
          this.o.onError(describeUdpError(err, "send", remote));
          return;
        }
        this.connected = true;
        this.ready();
        const queued = this.pending.splice(0);
        for (const b of queued) this.sendNow(b);
        if (this.overflow > 0) {
          this.o.onError(
            `${this.overflow} datagrams dropped while connecting to ${show(remote)} (more than ${MAX_PENDING} waiting)`,
          );
          this.overflow = 0;
        }
      });
    };
    if (isIP(remote.host) !== 0) {
      go(remote.host);
      return;
    }
    lookup(remote.host, { family: 4 }, (err, address) => {
      if (this.closed) return;
      if (err) this.o.onError(describeUdpError(err, "resolve", remote));
      else go(address);
    });
  }

  private readonly pending: Buffer[] = [];
  private overflow = 0;

  /**
   * Sends without a completion callback: Node then tries the send at once and reports a failure
   * as the socket's 'error' event (handled above), instead of scheduling a callback per datagram.
   */
  private sendNow(buf: Buffer, to?: Endpoint): void {
    try {
      if (to) this.socket.send(buf, to.port, to.host);
      else this.socket.send(buf);
    } catch (e) {
      this.o.onError(describeUdpError(e, "send", to ?? this.o.remote ?? { host: "?", port: 0 }));
    }
  }

  send(data: Uint8Array, to?: Endpoint): void {
    if (this.closed) return;
    // A copy: the caller reuses `data`, and a send that cannot leave at once is queued.
    const buf = Buffer.from(data);
    if (to) {
      if (this.connected) this.o.onError("send with an address on a connected socket");
      else this.sendNow(buf, to);
    } else if (this.connected) {
      this.sendNow(buf);
    } else if (this.o.remote) {
      if (this.pending.length < MAX_PENDING) this.pending.push(buf);
      else this.overflow++;
    } else {
      this.o.onError("send without a destination (the socket was opened without `remote`)");
    }
  }

  close(): void {
    if (this.closed) return;
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
