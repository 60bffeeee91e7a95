import { z } from "zod";
import {
  defineBlock,
  LegacyParamsError,
  vectorShape,
  type SerialHandle,
  type SerialStatus,
} from "../../engine";
import { ACTUATION_SIZE, controlInput, describeControl, toActuation } from "../control/actuation";
import { plural, TextThrottle } from "../shared/text";
import {
  ACK_LINE,
  ascii,
  CMD,
  DEFAULT_JOINT_MASK,
  DONGLE,
  handReference,
  LineSplitter,
  NACK_LINE,
  NEUTRAL_REFERENCE,
  packet,
  parseScanLine,
  REF,
  simultRefPayload,
  SUCCESS_LINE,
  UNITY_CONTROL,
  type ScannedDevice,
} from "./hannes-protocol";

/** The original's waits (HannesHand.cs), seconds. */
const WAIT = {
  /** After opening the port and after "$$$". */
  dongle: 0.5,
  /** For the scan table. */
  scan: 1.5,
  /** After "con N". */
  connect: 0.5,
  /** For the ACK of EnterCMDMode. */
  ping: 1,
  /** After configuring, before streaming. */
  configure: 1,
  /** Between "$$$" and "dct" when disconnecting. */
  disconnect: 2,
};
const MAX_SCANS = 3;

const params = z.strictObject({
  Port: z
    .string()
    .trim()
    .min(1)
    .max(256)
    .default("COM50")
    .describe(
      "The serial port of IIT's Rehab Dongle: COM50 (the original's default, on Windows), " +
        "/dev/ttyACM0 or /dev/ttyUSB0 on Linux, /dev/cu.… on macOS",
    ),
  Device: z
    .string()
    .trim()
    .min(1)
    .max(256)
    .optional()
    .describe(
      "The Hannes to connect to, by the name the dongle's scan lists; default: the first found",
    ),
  Connect: z
    .boolean()
    .default(true)
    .describe(
      "Connect when the pipeline starts (scan, connect, configure, then stream); false: with the " +
        "connect action (the original's control-panel buttons)",
    ),
  Input: z
    .enum(["auto", "actuation", "prediction"])
    .default("auto")
    .describe(
      "What the control input carries: actuation (a ControlAlgorithm's MOSAIC output, 11 values " +
        "0–100) or prediction (MOSAIC's 12–15 predictions 0–1, mapped as DirectControl); auto: by " +
        "its width",
    ),
  Reconnect: z
    .number()
    .min(0)
    .max(3600)
    .default(1)
    .describe("Seconds between attempts to reopen the port after it failed or vanished (0: never)"),
});

type Phase =
  | "unavailable"
  | "closed"
  | "waiting"
  | "opening"
  | "dongle"
  | "scanning"
  | "connecting"
  | "pinging"
  | "configuring"
  | "streaming"
  | "failed";

export const HannesHand = defineBlock({
  type: "HannesHand",
  category: "Devices",
  summary:
    "Drives IIT's Hannes prosthetic hand through its Bluetooth Rehab Dongle on a serial port: hand, wrist and thumb references.",
  help:
    "MOSAIC's HannesHand (docs/protocols.md, Hannes): talks to the IIT Hannes hand through the " +
    "Bluetooth Rehab Dongle on a serial port (115200 Bd). When the pipeline starts (or on the " +
    "`connect` action with `Connect: false`) it does what the original's control panel did: " +
    "puts the dongle in command mode (`$$$`), scans (`scan`, up to 3 times) and connects to " +
    "`Device` or the first Hannes found (`con N`), checks the link (the hand must ACK " +
    "EnterCMDMode), activates the thumb and wrist joints, selects the control mode the original " +
    "used (UNITY) and switches the hand to stream mode. Then every control event sends one " +
    "SimultRefControl packet: hand open/close (the Middle finger's actuation, 0–100), wrist " +
    "pronation/supination −(PS − 50)·2 and thumb rotation −(TR − 50)·2 (−100–100) and wrist " +
    "flexion/extension (0–100). Packets are `%`, command, payload, `&`, CR, LF. The control input " +
    "is a ControlAlgorithm's MOSAIC output (11 degrees of actuation) or a plain prediction vector " +
    "(12–15 values, mapped as DirectControl). Output `reference` [1, 4] carries hand, wrist P/S, " +
    "wrist F/E and thumb as sent (also before the hand is connected). On stop it sends the " +
    "original's neutral pose (hand open, F/E 80, P/S and thumb 0), returns the hand to command " +
    "mode and disconnects the dongle (`$$$`, then `dct`: 2 s later on the disconnect action, at " +
    "once when the pipeline stops). The status says each step " +
    "and why one failed (no answer to scan, no Hannes found, no ACK). Needs the desktop app or " +
    "`mosaic run` (the browser build has no serial ports). MOSAIC's positional form is " +
    "`[COMport]`, optional.",
  params,
  legacyParams(args) {
    if (args.length > 1) {
      throw new LegacyParamsError(
        `expected [COMport] or no Params (MOSAIC's HannesHand), got ${args.length} arguments`,
        "Port",
      );
    }
    const port = (args[0] ?? "").trim();
    return port === "" ? {} : { Port: port };
  },
  legacyForm: "[COMport], e.g. [ COM50 ] (optional: COM50)",
  inputs: { min: 1, max: 1, labels: ["control"] },
  outputs: ["reference"],
  eventLoop: true,
  views: ["scope", "label"],
  panel:
    "Connection steps and state, devices found by the scan, the four references sent; connect, disconnect and scan buttons.",
  create(ctx, p) {
    const control = controlInput(ctx, 0, p.Input, "Input");
    if (ctx.declaredRate === undefined) ctx.setDesiredRate(ctx.inputs[0]?.rate ?? 0);
    const out = ctx.output(vectorShape(4), "reference");
    const act = new Float64Array(ACTUATION_SIZE);
    const ref = new Float64Array(4);
    const reads = describeControl(control);
    const lines = new LineSplitter();
    const throttle = new TextThrottle();

    let phase: Phase = "closed";
    let detail = "";
    let handle: SerialHandle | undefined;
    let portOpen = false;
    let wantConnect = p.Connect;
    let wanted = p.Device;
    let received: string[] = [];
    const devices: ScannedDevice[] = [];
    let device: ScannedDevice | undefined;
    let attempt = 0;
    let sent = 0;
    let nacks = 0;
    let gen = 0;

    const describe = (): void => {
      let s: string;
      switch (phase) {
        case "unavailable":
          s =
            "serial ports are not available here (browser build): run the pipeline with mosaic run or the desktop app";
          break;
        case "closed":
          s = `${p.Port} closed`;
          break;
        case "waiting":
          s = `${p.Port} open; press connect to find the Hannes`;
          break;
        case "opening":
          s = `opening ${p.Port}… ${detail}`.trim();
          break;
        case "dongle":
          s = `${p.Port}: dongle in command mode…`;
          break;
        case "scanning":
          s = `${p.Port}: scanning for a Hannes (attempt ${attempt} of ${MAX_SCANS})…`;
          break;
        case "connecting":
          s = `${p.Port}: connecting to ${device?.name ?? "?"}…`;
          break;
        case "pinging":
          s = `${p.Port}: waiting for ${device?.name ?? "the hand"} to acknowledge…`;
          break;
        case "configuring":
          s = `${p.Port}: configuring ${device?.name ?? "the hand"}…`;
          break;
        case "streaming":
          s = `${device?.name ?? "Hannes"} on ${p.Port}, ${reads}: ${plural(sent, "reference")} sent`;
          break;
        case "failed":
          s = `${p.Port}: ${detail}`;
          break;
      }
      if (nacks > 0) s += ` · ${nacks} NACK`;
      ctx.setText(s);
    };

    const write = (b: Uint8Array): void => handle?.write(b);
    /** Runs `fn` after `seconds`, unless something else happened in between. */
    const after = (seconds: number, fn: () => void): void => {
      const g = ++gen;
      ctx.at(ctx.now() + seconds, () => {
        if (g === gen) fn();
      });
    };
    const fail = (why: string): void => {
      gen++;
      phase = "failed";
      detail = why;
      ctx.warn(`${p.Port}: ${why}`);
      describe();
    };

    const connectTo = (d: ScannedDevice): void => {
      device = d;
      phase = "connecting";
      write(ascii(DONGLE.connect(d.con)));
      describe();
      after(WAIT.connect, () => {
        received = [];
        phase = "pinging";
        describe();
        // The timeout first: the ACK (which moves on) may arrive while the packet is written.
        after(WAIT.ping, () =>
          fail(
            `${d.name} did not acknowledge (no ACK to EnterCMDMode within ${WAIT.ping} s): is it on and in range?`,
          ),
        );
        write(packet([CMD.EnterCMDMode]));
      });
    };
    const configure = (): void => {
      phase = "configuring";
      write(packet([CMD.RefControl, REF.JOINT_SET, DEFAULT_JOINT_MASK]));
      write(packet([CMD.RefControl, REF.CONTROL_MODE, UNITY_CONTROL]));
      write(packet([CMD.ExitCMDMode]));
      describe();
      after(WAIT.configure, () => {
        phase = "streaming";
        describe();
      });
    };
    const scan = (): void => {
      attempt++;
      received = [];
      phase = "scanning";
      describe();
      after(WAIT.scan, () => {
        if (!received.includes(SUCCESS_LINE)) {
          if (attempt < MAX_SCANS) scan();
          else
            fail("the dongle did not answer the scan: is it plugged in? Unplug and reconnect it");
          return;
        }
        for (const l of received) {
          const d = parseScanLine(l);
          if (d && !devices.some((x) => x.address === d.address)) devices.push(d);
        }
        if (devices.length === 0) {
          fail("no Hannes found by the scan: is the hand switched on?");
          return;
        }
        const d = wanted === undefined ? devices[0] : devices.find((x) => x.name === wanted);
        if (!d) {
          fail(`'${wanted}' not found; the scan found ${devices.map((x) => x.name).join(", ")}`);
          return;
        }
        connectTo(d);
      });
      write(ascii(DONGLE.scan));
    };
    const begin = (): void => {
      attempt = 0;
      device = undefined;
      phase = "dongle";
      after(WAIT.dongle, () => {
        write(ascii(DONGLE.commandMode));
        after(WAIT.dongle, scan);
      });
      describe();
    };

    const onLine = (line: string): void => {
      received.push(line);
      if (received.length > 1000) received.shift();
      if (line === NACK_LINE) {
        nacks++;
        describe();
      } else if (phase === "pinging" && line === ACK_LINE) {
        configure();
      }
    };

    const onStatus = (s: SerialStatus, msg?: string): void => {
      if (s === "open") {
        portOpen = true;
        lines.reset();
        if (wantConnect) begin();
        else {
          phase = "waiting";
          describe();
        }
        return;
      }
      const was = portOpen;
      portOpen = false;
      gen++;
      if (s === "error") {
        const news = was || phase !== "opening" || detail !== (msg ?? "");
        phase = "opening";
        detail = msg ?? "";
        if (news) ctx.warn(`${p.Port}: ${msg ?? "error"}`);
      } else if (s === "closed") {
        phase = "closed";
      }
      describe();
    };

    /**
     * The original's disconnect: neutral pose, the hand back to command mode, then "$$$" and the
     * dongle's "dct" 2 s later (`wait`: the pipeline runs, so the wait is a timer; at stop both go
     * at once, and the port closes).
     */
    const disconnect = (wait: boolean): void => {
      gen++;
      const h = handle;
      if (!h) return;
      if (phase === "streaming" || phase === "configuring") {
        h.write(packet(simultRefPayload(NEUTRAL_REFERENCE)));
        h.write(packet([CMD.EnterCMDMode]));
      }
      h.write(ascii(DONGLE.commandMode));
      const finish = (): void => {
        h.write(ascii(DONGLE.disconnect));
        h.close();
      };
      handle = undefined;
      portOpen = false;
      if (wait) {
        // Not through `after`: a reconnect in the meantime must not cancel it.
        ctx.at(ctx.now() + WAIT.disconnect, finish);
      } else finish();
      phase = "closed";
      device = undefined;
      describe();
    };

    let started = false;
    const open = (): void => {
      const bridge = ctx.io.serial;
      if (!bridge) {
        phase = "unavailable";
        ctx.warn(
          "serial ports are not available here (browser build): the Hannes hand gets nothing",
        );
        describe();
        return;
      }
      if (handle) return;
      phase = "opening";
      detail = "";
      handle = bridge.open({
        path: p.Port,
        baudRate: 115200,
        dataBits: 8,
        stopBits: 1,
        parity: "none",
        reconnectMs: p.Reconnect * 1000,
        onData: (b) => lines.push(b, onLine),
        onStatus,
      });
      describe();
    };

    describe();
    return {
      start() {
        started = true;
        open();
      },
      stop() {
        started = false;
        disconnect(false);
      },
      process(f) {
        const n = f.n;
        if (n === 0) return;
        const o = out.frame(n);
        for (let e = 0; e < n; e++) {
          o.t[e] = f.t[e]!;
          toActuation(control, f.v, e, act);
          handReference(act, ref);
          o.v.set(ref, e * 4);
          if (phase === "streaming" && handle) {
            handle.write(packet(simultRefPayload(ref)));
            sent++;
          }
        }
        out.emit(o);
        if (throttle.due(f.t[n - 1]!)) describe();
      },
      reset() {
        sent = 0;
        nacks = 0;
        throttle.reset();
        describe();
      },
      dispose() {
        gen++;
        handle?.close();
        handle = undefined;
      },
      actions: {
        connect: {
          label: "Connect",
          description:
            "Scan and connect to a Hannes (a name, or the Device param / the first found)",
          run(arg) {
            if (typeof arg === "string" && arg.trim() !== "") wanted = arg.trim();
            wantConnect = true;
            if (!started) return "start the pipeline first";
            if (!handle) {
              open();
              return `opening ${p.Port}; it connects then`;
            }
            if (!portOpen) return `waiting for ${p.Port} to open; it connects then`;
            begin();
            return `scanning for ${wanted ?? "a Hannes"}`;
          },
        },
        disconnect: {
          label: "Disconnect",
          description: "Neutral pose, then disconnect the hand (the port closes)",
          run() {
            if (!handle) return "not connected";
            disconnect(true);
            return "disconnecting";
          },
        },
        devices: {
          label: "Devices",
          description: "The Hannes devices the scans found",
          run: () =>
            devices.length === 0
              ? "none found yet"
              : devices.map((d) => `${d.name} (${d.address}, RSSI ${d.rssi})`).join("; "),
        },
      },
    };
  },
});
