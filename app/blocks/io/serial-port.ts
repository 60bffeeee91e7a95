import { z } from "zod";
import { BlockConfigError, defineBlock, shapeSize, vectorShape } from "../../engine";
import {
  CHECKSUMS,
  FIELD_TYPES,
  lineDecoder,
  lineEncoder,
  structDecoder,
  structEncoder,
  structSize,
  type Decoder,
  type Encoder,
} from "./serial-framing";
import { SerialPortRun } from "./serial-port-run";

const params = z.strictObject({
  Path: z
    .string()
    .min(1)
    .describe(
      "The serial device: /dev/ttyUSB0, /dev/ttyACM0 (Linux), /dev/tty.usbmodem… (macOS), COM3 (Windows)",
    ),
  BaudRate: z.number().int().positive().default(115200).describe("Bits per second"),
  DataBits: z
    .union([z.literal(5), z.literal(6), z.literal(7), z.literal(8)])
    .default(8)
    .describe("Data bits per character"),
  StopBits: z
    .union([z.literal(1), z.literal(1.5), z.literal(2)])
    .default(1)
    .describe("Stop bits per character"),
  Parity: z.enum(["none", "even", "odd", "mark", "space"]).default("none").describe("Parity bit"),
  Framing: z
    .enum(["lines", "binary"])
    .default("lines")
    .describe(
      "lines: one vector per text line, numbers separated by commas, semicolons, tabs or spaces; " +
        "binary: fixed-size frames of Sync bytes, Fields and a Checksum",
    ),
  Channels: z
    .number()
    .int()
    .positive()
    .max(4096)
    .optional()
    .describe("Values per frame (lines framing: required; binary: the number of Fields)"),
  Fields: z
    .array(z.enum(FIELD_TYPES))
    .max(4096)
    .default([])
    .describe("Binary framing: the type of each value in a frame, e.g. [i16, i16, f32]"),
  Sync: z
    .array(z.number().int().min(0).max(255))
    .max(16)
    .default([])
    .describe("Binary framing: bytes that start every frame, e.g. [0xAA, 0x55] written [170, 85]"),
  Checksum: z
    .enum(CHECKSUMS)
    .default("none")
    .describe(
      "Binary framing: over the fields (not the sync bytes): xor8, sum8 (mod 256) or crc16 " +
        "(CCITT-FALSE, in the frame's byte order)",
    ),
  Endianness: z.enum(["little", "big"]).default("little").describe("Binary framing: byte order"),
  Reconnect: z
    .number()
    .min(0)
    .max(3600)
    .default(1)
    .describe(
      "Seconds between attempts to reopen the port after an unplug or a failed open (0: never)",
    ),
});

type Params = z.output<typeof params>;

function framingOf(p: Params): { channels: number; decoder: Decoder; encoder: Encoder } {
  if (p.Framing === "lines") {
    if (p.Channels === undefined) {
      throw new BlockConfigError("lines framing needs Channels (values per line)", "Channels");
    }
    if (p.Fields.length > 0) {
      throw new BlockConfigError(
        "Fields apply to binary framing only (set Framing: binary)",
        "Fields",
      );
    }
    return {
      channels: p.Channels,
      decoder: lineDecoder({ channels: p.Channels }),
      encoder: lineEncoder(),
    };
  }
  if (p.Fields.length === 0) {
    throw new BlockConfigError("binary framing needs Fields (the type of each value)", "Fields");
  }
  if (p.Channels !== undefined && p.Channels !== p.Fields.length) {
    throw new BlockConfigError(
      `Channels is ${p.Channels} but Fields lists ${p.Fields.length} values`,
      "Channels",
    );
  }
  const o = {
    fields: p.Fields,
    sync: p.Sync,
    checksum: p.Checksum,
    littleEndian: p.Endianness === "little",
  };
  return { channels: p.Fields.length, decoder: structDecoder(o), encoder: structEncoder(o) };
}

export const SerialPort = defineBlock({
  type: "SerialPort",
  category: "Devices",
  summary: "Reads vectors from a serial device and writes its input's vectors to it.",
  help:
    "A device on a serial port (USB CDC, FTDI, Bluetooth SPP), as MOSAIC's serial interface " +
    "(paper III-E.5): every frame the device sends becomes one event [1, Channels] stamped with " +
    "its arrival time; every event of the optional input is written to the device in the same " +
    "framing. `lines`: one vector per text line (`12.5,-3,7`; commas, semicolons, tabs or " +
    "spaces; `\\n` or `\\r\\n`). `binary`: fixed-size frames of `Sync` bytes, one value per " +
    "`Fields` entry (i8…u32, f32, f64; `Endianness`) and an optional `Checksum` over the fields " +
    "(xor8, sum8, CRC-16/CCITT-FALSE); a frame with a bad checksum is dropped and the decoder " +
    "re-synchronises on the next sync bytes. Malformed lines and frames are counted and shown " +
    "in the status, never fatal. When the device disappears (unplugged, powered off) the status " +
    "says so and the port is reopened every `Reconnect` seconds; data resumes when it is back. " +
    "Needs the desktop app or `mosaic run` (the browser build has no serial ports: the block " +
    "says so in its status and the rest of the pipeline runs).",
  params,
  inputs: { min: 0, max: 1, labels: ["to device"] },
  eventLoop: true,
  views: ["scope", "label"],
  panel: "The values the device sends; the port's state, frames decoded, malformed frames.",
  create(ctx, p) {
    const { channels, decoder, encoder } = framingOf(p);
    const input = ctx.inputs[0];
    if (input?.shape && p.Framing === "binary" && shapeSize(input.shape) !== channels) {
      throw new BlockConfigError(
        `the input ${input.source} carries ${shapeSize(input.shape)} values per event, but a binary frame holds ${channels} Fields`,
        "Fields",
      );
    }
    const out = ctx.output(vectorShape(channels));
    const info = (): string =>
      `${p.Path} ${p.BaudRate} Bd ${p.DataBits}${p.Parity[0]!.toUpperCase()}${p.StopBits}, ` +
      `${p.Framing}${p.Framing === "binary" ? ` (${structSize({ fields: p.Fields, sync: p.Sync, checksum: p.Checksum, littleEndian: true })} bytes/frame)` : ""}`;
    return new SerialPortRun(ctx, p, decoder, encoder, out, info).instance();
  },
});
