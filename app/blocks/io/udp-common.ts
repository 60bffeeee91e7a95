/** Params and helpers shared by the UDP blocks. */
import { z } from "zod";
import type { BlockContext, UdpBridge } from "../../engine";

export const hostParam = (what: string) =>
  z
    .string()
    .trim()
    .min(1)
    .max(253)
    .regex(/^[A-Za-z0-9.:_%-]+$/, "expected an IP address or a host name")
    .default("127.0.0.1")
    .describe(what);

export const portParam = (what: string) => z.number().int().min(1).max(65535).describe(what);

export const formatParam = z
  .enum(["streamlined", "f32", "f64"])
  .default("streamlined")
  .describe(
    "Wire format (docs/protocols.md): streamlined = MOSAIC's UDP_StreamlinedSender datagram " +
      "(count, type byte, category, subcategory, f64 timestamp, values, u16 counter); " +
      "f32 / f64 = raw little-endian vectors without a header",
  );

export const byteParam = (what: string) => z.number().int().min(0).max(255).describe(what);

/** `[::1]:5000`, `127.0.0.1:5000`. */
export const endpointText = (host: string, port: number): string =>
  host.includes(":") ? `[${host}]:${port}` : `${host}:${port}`;

/** The start of every message saying a block has no UDP here. */
export const NO_UDP = "UDP is unavailable here (the browser build has no network sockets)";

/** The host's UDP bridge, or undefined after saying in the block's status why there is none. */
export function udpBridge(ctx: BlockContext): UdpBridge | undefined {
  const udp = ctx.io.udp;
  if (udp) return udp;
  ctx.setText(`${NO_UDP}: run the pipeline with the desktop app or \`mosaic run\``);
  return undefined;
}

/** Warnings at most every `interval` seconds of clock time, with how many were held back. */
export class WarnLimiter {
  private last = -Infinity;
  private held = 0;

  constructor(
    private readonly ctx: BlockContext,
    private readonly interval = 2,
  ) {}

  warn(message: string): void {
    const now = this.ctx.now();
    if (now - this.last < this.interval && now >= this.last) {
      this.held++;
      return;
    }
    this.last = now;
    const more = this.held > 0 ? ` (${this.held} similar messages held back)` : "";
    this.held = 0;
    this.ctx.warn(message + more);
  }

  reset(): void {
    this.last = -Infinity;
    this.held = 0;
  }
}
