/**
 * The UI protocol over text transports (WebSocket): JSON that keeps what structured cloning
 * keeps and JSON loses. Float64Arrays travel as base64 of their little-endian bytes (exact, and
 * four times smaller than number lists), and non-finite numbers (NaN R² before an output varies,
 * ±Infinity) as `{"$n": "NaN"}` instead of becoming `null`.
 */

/**
 * WebSocket close codes `mosaic serve` refuses a socket with, before any message (the reason
 * says why in words): a wrong or missing token, a page from another origin.
 */
export const CLOSE_BAD_TOKEN = 4401;
export const CLOSE_FOREIGN_ORIGIN = 4403;

const B64 = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
const LOOKUP = new Int16Array(128).fill(-1);
for (let i = 0; i < B64.length; i++) LOOKUP[B64.charCodeAt(i)] = i;

const littleEndian = new Uint8Array(new Uint16Array([1]).buffer)[0] === 1;

export function bytesToBase64(bytes: Uint8Array): string {
  let out = "";
  let i = 0;
  for (; i + 2 < bytes.length; i += 3) {
    const n = (bytes[i]! << 16) | (bytes[i + 1]! << 8) | bytes[i + 2]!;
    out += B64[n >> 18]! + B64[(n >> 12) & 63]! + B64[(n >> 6) & 63]! + B64[n & 63]!;
  }
  const rest = bytes.length - i;
  if (rest === 1) {
    const n = bytes[i]! << 16;
    out += B64[n >> 18]! + B64[(n >> 12) & 63]! + "==";
  } else if (rest === 2) {
    const n = (bytes[i]! << 16) | (bytes[i + 1]! << 8);
    out += B64[n >> 18]! + B64[(n >> 12) & 63]! + B64[(n >> 6) & 63]! + "=";
  }
  return out;
}

export function base64ToBytes(text: string): Uint8Array {
  const clean = text.replace(/=+$/, "");
  if (clean.length % 4 === 1) throw new Error("invalid base64 length");
  const out = new Uint8Array(Math.floor((clean.length * 3) / 4));
  let o = 0;
  for (let i = 0; i < clean.length; i += 4) {
    let n = 0;
    const chunk = Math.min(4, clean.length - i);
    for (let k = 0; k < 4; k++) {
      const c = k < chunk ? clean.charCodeAt(i + k) : 65; // 'A' pads
      const v = c < 128 ? LOOKUP[c]! : -1;
      if (v < 0) throw new Error(`invalid base64 character at ${i + k}`);
      n = (n << 6) | v;
    }
    out[o++] = (n >> 16) & 255;
    if (chunk > 2) out[o++] = (n >> 8) & 255;
    if (chunk > 3) out[o++] = n & 255;
  }
  return out.subarray(0, o);
}

function f64ToBase64(a: Float64Array): string {
  const bytes = new Uint8Array(a.buffer, a.byteOffset, a.byteLength);
  if (littleEndian) return bytesToBase64(bytes);
  const copy = new Uint8Array(a.byteLength);
  const view = new DataView(copy.buffer);
  for (let i = 0; i < a.length; i++) view.setFloat64(i * 8, a[i]!, true);
  return bytesToBase64(copy);
}

function base64ToF64(text: string): Float64Array {
  const bytes = base64ToBytes(text);
  if (bytes.length % 8 !== 0) throw new Error("a Float64Array's bytes are not a multiple of 8");
  const out = new Float64Array(bytes.length / 8);
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  for (let i = 0; i < out.length; i++) out[i] = view.getFloat64(i * 8, true);
  return out;
}

/** Encodes a protocol message (either direction) as one JSON text. */
export function encodeWire(msg: unknown): string {
  return JSON.stringify(msg, function (this: unknown, key: string, value: unknown) {
    // `value` of a typed array has already been through toJSON-less conversion: read the holder.
    const raw = (this as Record<string, unknown>)[key];
    if (raw instanceof Float64Array) return { $f64: f64ToBase64(raw) };
    if (typeof value === "number" && !Number.isFinite(value)) return { $n: String(value) };
    return value;
  });
}

/** Decodes what `encodeWire` wrote; throws on text that is not JSON. */
export function decodeWire(text: string): unknown {
  return JSON.parse(text, (_key, value: unknown) => {
    if (value !== null && typeof value === "object" && !Array.isArray(value)) {
      const o = value as Record<string, unknown>;
      const keys = Object.keys(o);
      if (keys.length === 1 && typeof o.$f64 === "string") return base64ToF64(o.$f64);
      if (keys.length === 1 && typeof o.$n === "string") {
        if (o.$n === "NaN") return NaN;
        if (o.$n === "Infinity") return Infinity;
        if (o.$n === "-Infinity") return -Infinity;
      }
    }
    return value;
  });
}
