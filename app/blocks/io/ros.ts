import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  errorMessage,
  legacyInteger,
  LegacyParamsError,
  vectorShape,
  type OutputPort,
  type RosBridge,
  type RosConnection,
  type RosConnectionState,
  type RosPublisher,
  type RosSubscription,
} from "../../engine";
import { signalInput } from "../shared/inputs";
import { formatCount, plural, TextThrottle } from "../shared/text";
import {
  fixedSizeOf,
  ROS_MESSAGE_TYPES,
  rosDecoder,
  rosEncoder,
  type RosDecoder,
  type RosEncoder,
} from "./ros-messages";
import { WarnLimiter } from "./udp-common";

/** A ROS graph resource name: `/a/b_c`, `a`, `~/private` (no `//`, no trailing `/`). */
const TOPIC_NAME = /^(~\/|\/)?[A-Za-z_][A-Za-z0-9_]*(\/[A-Za-z_][A-Za-z0-9_]*)*$/;

const params = z.strictObject({
  Url: z
    .string()
    .trim()
    .max(2048)
    .regex(/^wss?:\/\/[^\s/?#]+(\/[^\s]*)?$/, "expected a WebSocket URL: ws://host:port")
    .default("ws://127.0.0.1:9090")
    .describe(
      "The rosbridge server (rosbridge_websocket, by default on port 9090): ws://host:port, or wss:// for TLS",
    ),
  Topic: z
    .string()
    .trim()
    .max(256)
    .regex(TOPIC_NAME, "expected a ROS topic name such as /mosaic/command")
    .describe("The ROS topic to publish to or subscribe to, e.g. /cmd_vel"),
  Direction: z
    .enum(["publish", "subscribe"])
    .default("publish")
    .describe(
      "publish: every input event becomes one message on Topic; subscribe: every message on Topic becomes one event",
    ),
  MessageType: z
    .enum(ROS_MESSAGE_TYPES)
    .default("std_msgs/Float64MultiArray")
    .describe(
      "The ROS message type, mapped to and from a flat vector (docs/protocols.md): " +
        "Float64MultiArray / Float32MultiArray = data (any length); Float64 = [data]; " +
        "Vector3 = [x, y, z]; Twist = [linear.xyz, angular.xyz]; JointState = position",
    ),
  Channels: z
    .number()
    .int()
    .min(1)
    .max(65536)
    .optional()
    .describe(
      "Values per message. Subscribe: the width of the output (required for the array types; " +
        "messages of another length are counted as malformed). Publish: taken from the input " +
        "(if given, it must match)",
    ),
  JointNames: z
    .array(z.string().min(1).max(256))
    .min(1)
    .max(65536)
    .optional()
    .describe(
      "sensor_msgs/JointState only: the joint of each value. Publish: sent as `name`; " +
        "subscribe: positions are picked by name (in this order) instead of by position",
    ),
  ReconnectSeconds: z
    .number()
    .min(0)
    .max(3600)
    .default(1)
    .describe(
      "Seconds before the first attempt to reconnect after a lost connection or a failed " +
        "attempt; each further failure doubles the wait, up to ReconnectMaxSeconds (0: never reconnect)",
    ),
  ReconnectMaxSeconds: z
    .number()
    .min(0.01)
    .max(3600)
    .default(30)
    .describe("The longest wait between two attempts to reconnect"),
  ThrottleMs: z
    .number()
    .int()
    .min(0)
    .max(3_600_000)
    .optional()
    .describe(
      "Subscribe only: rosbridge's throttle_rate, the least time in ms between two messages it " +
        "forwards (default 0: every message)",
    ),
  QueueLength: z
    .number()
    .int()
    .min(0)
    .max(100_000)
    .optional()
    .describe(
      "Subscribe only: rosbridge's queue_length, messages it keeps while throttling (default 0)",
    ),
  Latch: z
    .boolean()
    .optional()
    .describe("Publish only: latch the topic (late subscribers get the last message)"),
});

type Params = z.output<typeof params>;

/** "0.3 s", "12 s". */
const seconds = (s: number): string =>
  s < 1 ? `${Math.max(0.1, Math.ceil(s * 10) / 10)} s` : `${Math.ceil(s - 1e-9)} s`;

function checkParams(p: Params): void {
  const publish = p.Direction === "publish";
  const sub = ["ThrottleMs", "QueueLength"] as const;
  for (const k of publish ? sub : (["Latch"] as const)) {
    if (p[k] !== undefined) {
      throw new BlockConfigError(
        `${k} applies to Direction ${publish ? "subscribe" : "publish"} only`,
        k,
      );
    }
  }
  if (p.JointNames !== undefined) {
    if (p.MessageType !== "sensor_msgs/JointState") {
      throw new BlockConfigError(
        `JointNames apply to sensor_msgs/JointState, not ${p.MessageType}`,
        "JointNames",
      );
    }
    const seen = new Set<string>();
    for (const n of p.JointNames) {
      if (seen.has(n)) throw new BlockConfigError(`joint '${n}' is named twice`, "JointNames");
      seen.add(n);
    }
  }
  if (p.ReconnectSeconds > p.ReconnectMaxSeconds) {
    throw new BlockConfigError(
      `ReconnectSeconds (${p.ReconnectSeconds}) is longer than ReconnectMaxSeconds (${p.ReconnectMaxSeconds})`,
      "ReconnectMaxSeconds",
    );
  }
}

export const Ros = defineBlock({
  type: "ROS",
  category: "Communication",
  summary:
    "Publishes its input to a ROS topic, or emits the messages of a ROS topic, through rosbridge.",
  help:
    "Connects the pipeline to ROS 1 or ROS 2 through a **rosbridge** server (rosbridge_suite's " +
    "`rosbridge_websocket`, the rosbridge v2 JSON protocol over a WebSocket at `Url`). " +
    "`Direction: publish` advertises `Topic` and sends every input event as one message; " +
    "`Direction: subscribe` subscribes to `Topic` and emits every message as one event " +
    "[1, Channels], stamped with its arrival time. Messages map to flat vectors " +
    "(docs/protocols.md): **std_msgs/Float64MultiArray** (default) and " +
    "**std_msgs/Float32MultiArray** ↔ `data` (any length; a matrix input is published with a " +
    "rows × cols layout; float32 values are rounded), **std_msgs/Float64** ↔ `[data]`, " +
    "**geometry_msgs/Vector3** ↔ `[x, y, z]`, **geometry_msgs/Twist** ↔ `[linear.x, linear.y, " +
    "linear.z, angular.x, angular.y, angular.z]`, **sensor_msgs/JointState** ↔ `position` (with " +
    "`JointNames` sent as `name`, and when subscribing picked by name). Received messages that " +
    "do not fit (another length, a missing field) are counted as malformed and shown in the " +
    "status, never thrown. Events holding NaN or ±∞ are not published (JSON has no such " +
    "numbers) but counted. When the connection is refused or lost the status says so and " +
    "counts down to the next attempt: `ReconnectSeconds`, doubling after each failure up to " +
    "`ReconnectMaxSeconds`; events to publish meanwhile are dropped and counted, never queued " +
    "(stale commands must not reach a robot late). Needs the desktop app or `mosaic run` (the " +
    "browser build has no rosbridge connection: the status says so). MOSAIC's positional form " +
    "`[host, publish|subscribe, topic, messageType, channels]` loads as Url ws://host:9090 " +
    "(rosbridge's default port, as MOSAIC connected), Direction, /topic, MessageType and, for a " +
    "subscriber, Channels. MOSAIC's subscriber reshaped a message of several samples " +
    "channel-major; here a message is one event of Channels values, others are malformed.",
  params,
  legacyParams(args) {
    if (args.length < 4 || args.length > 5) {
      throw new LegacyParamsError(
        `expected [host, publish|subscribe, topic, messageType, channels] (MOSAIC's ROS), got ${args.length} argument${args.length === 1 ? "" : "s"}`,
      );
    }
    const host = args[0]!.trim();
    if (host === "") throw new LegacyParamsError("the host (first argument) is empty", "Url");
    const direction = args[1]!.trim().toLowerCase();
    if (direction !== "publish" && direction !== "subscribe") {
      throw new LegacyParamsError(
        `the second argument '${args[1]!.trim()}' is neither publish nor subscribe`,
        "Direction",
      );
    }
    const topic = args[2]!.trim();
    const out: Record<string, unknown> = {
      // MOSAIC connected to rosbridge's default port and put a '/' before the topic.
      Url: `ws://${host.includes(":") && !host.startsWith("[") ? `[${host}]` : host}:9090`,
      Direction: direction,
      Topic: topic.startsWith("/") ? topic : `/${topic}`,
      MessageType: args[3]!.trim().replace(/^\//, ""),
    };
    // A publisher's width is its input's (MOSAIC read the number but did not use it).
    if (direction === "subscribe") {
      if (args[4] === undefined) {
        throw new LegacyParamsError(
          "a subscriber needs the number of channels as fifth argument",
          "Channels",
        );
      }
      out.Channels = legacyInteger(args[4], "the number of channels", "Channels");
    }
    return out;
  },
  legacyForm:
    "[host, publish|subscribe, topic, messageType, channels], e.g. [localhost, subscribe, " +
    "example_topic1, std_msgs/Float64MultiArray, 10] (rosbridge at ws://host:9090, the topic " +
    "under /; a publisher's channels are its input's)",
  inputs: { min: 0, max: 1, labels: ["to publish"] },
  outputs: (p: Params) => (p.Direction === "subscribe" ? ["out"] : []),
  eventLoop: true,
  views: ["scope", "label"],
  panel: "Connection state, messages in and out, the reconnect countdown; received values.",
  create(ctx, p) {
    checkParams(p);
    const publish = p.Direction === "publish";
    const type = p.MessageType;
    const fixed = fixedSizeOf(type);
    let size: number;
    let encoder: RosEncoder | undefined;
    let decoder: RosDecoder | undefined;
    let out: OutputPort | undefined;
    if (publish) {
      if (ctx.inputs.length === 0) {
        throw new BlockConfigError(
          "Direction publish needs an input (the values to publish); to receive messages set Direction: subscribe",
          "Direction",
        );
      }
      const input = signalInput(ctx, 0);
      size = input.size;
      if (fixed !== undefined && size !== fixed) {
        throw new BlockConfigError(
          `a ${type} message carries ${fixed} value${fixed === 1 ? "" : "s"}, but the input '${input.info.source}' has ${size}`,
          "MessageType",
        );
      }
      if (p.Channels !== undefined && p.Channels !== size) {
        throw new BlockConfigError(
          `Channels is ${p.Channels} but the input '${input.info.source}' carries ${size} values per event`,
          "Channels",
        );
      }
      encoder = rosEncoder(type, {
        size,
        rows: input.shape.rows,
        cols: input.shape.cols,
        ...(p.JointNames ? { jointNames: p.JointNames } : {}),
      });
    } else {
      if (ctx.inputs.length > 0) {
        throw new BlockConfigError(
          "Direction subscribe takes no input (it emits the messages of Topic); to send the input set Direction: publish",
          "Direction",
        );
      }
      if (fixed !== undefined && p.Channels !== undefined && p.Channels !== fixed) {
        throw new BlockConfigError(
          `a ${type} message carries ${fixed} value${fixed === 1 ? "" : "s"}, not Channels ${p.Channels}`,
          "Channels",
        );
      }
      const n = p.Channels ?? fixed ?? p.JointNames?.length;
      if (n === undefined) {
        throw new BlockConfigError(
          `Channels is needed to subscribe to ${type} (the values per message: the width of the output)`,
          "Channels",
        );
      }
      size = n;
      decoder = rosDecoder(type, {
        size,
        ...(p.JointNames ? { jointNames: p.JointNames } : {}),
      });
      out = ctx.output(vectorShape(size));
    }
    if (p.JointNames !== undefined && p.JointNames.length !== size) {
      throw new BlockConfigError(
        `JointNames lists ${p.JointNames.length} joints for ${size} values: give one name per value`,
        "JointNames",
      );
    }

    const url = p.Url;
    const topic = p.Topic;
    const bridge: RosBridge | undefined = ctx.io.ros;
    const warns = new WarnLimiter(ctx);
    const throttle = new TextThrottle();
    const scratch = new Float64Array(size);

    type State = "idle" | "unavailable" | "connecting" | "connected" | "waiting" | "stopped";
    let state: State = bridge ? "idle" : "unavailable";
    let conn: RosConnection | undefined;
    let pub: RosPublisher | undefined;
    let sub: RosSubscription | undefined;
    /** Each connection attempt gets a number; callbacks of older attempts are ignored. */
    let attempt = 0;
    let running = false;
    let reason = "";
    /** Failed attempts (or lost connections) since the last successful connection. */
    let failures = 0;
    let connections = 0;
    let retryAt = Infinity;
    let sent = 0;
    let received = 0;
    let dropped = 0;
    let skipped = 0;
    let malformed = 0;
    let lastMalformed = "";
    let lastText = "";

    const describe = (): void => {
      let text: string;
      if (state === "unavailable") {
        text =
          "ROS is unavailable here (the browser build has no rosbridge connection): run the " +
          "pipeline with the desktop app or `mosaic run`";
        if (dropped > 0) text += ` · ${formatCount(dropped)} not sent`;
        if (text !== lastText) ctx.setText((lastText = text));
        return;
      }
      const what = `${publish ? "publishing" : "subscribed to"} ${topic} (${type})`;
      switch (state) {
        case "idle":
          text = `${url} · ${what}`;
          break;
        case "connecting":
          text = `connecting to ${url}${failures > 0 ? ` (attempt ${failures + 1})` : ""}… · ${what}`;
          break;
        case "connected":
          text = `connected to ${url} · ${what}`;
          break;
        case "waiting": {
          const wait =
            retryAt === Infinity
              ? "not reconnecting (ReconnectSeconds 0)"
              : `reconnecting in ${seconds(retryAt - ctx.now())} (attempt ${failures + 1})`;
          text = `disconnected from ${url}: ${reason}; ${wait} · ${what}`;
          break;
        }
        case "stopped":
          text = `stopped · ${what}`;
          break;
      }
      text += publish ? ` · ${formatCount(sent)} out` : ` · ${formatCount(received)} in`;
      if (connections > 1) text += ` · ${plural(connections - 1, "reconnect")}`;
      if (dropped > 0) text += ` · ${formatCount(dropped)} dropped while disconnected`;
      if (skipped > 0) text += ` · ${formatCount(skipped)} not sent (NaN or ±∞)`;
      if (malformed > 0) text += ` · ${formatCount(malformed)} malformed (last: ${lastMalformed})`;
      if (text !== lastText) ctx.setText((lastText = text));
    };
    describe();

    const closeConnection = (): void => {
      const c = conn;
      const s = sub;
      const pb = pub;
      conn = undefined;
      sub = undefined;
      pub = undefined;
      try {
        s?.unsubscribe();
        pb?.unadvertise();
        c?.close();
      } catch (e) {
        warns.warn(`closing the connection to ${url}: ${errorMessage(e)}`);
      }
    };

    const onMessage = (msg: unknown): void => {
      if (!running || !out || !decoder) return;
      const now = ctx.now();
      const err = decoder.decode(msg, scratch);
      if (err !== undefined) {
        malformed++;
        lastMalformed = err;
        warns.warn(`malformed ${type} message on ${topic}: ${err} (${malformed} so far)`);
        describe();
        return;
      }
      const f = out.frame(1);
      f.t[0] = now;
      f.v.set(scratch);
      received++;
      out.emit(f);
      if (throttle.due(now)) describe();
    };

    /** The one-shot: refreshes the countdown every second and reconnects when it is due. */
    const countdown = (): void => {
      if (!running || state !== "waiting") return;
      const now = ctx.now();
      if (now >= retryAt - 1e-6) {
        connect();
        return;
      }
      describe();
      ctx.at(Math.min(retryAt, now + 1), countdown);
    };

    const lost = (message: string): void => {
      const wasConnected = state === "connected";
      closeConnection();
      reason = message;
      failures++;
      state = "waiting";
      if (p.ReconnectSeconds > 0) {
        const wait = Math.min(p.ReconnectMaxSeconds, p.ReconnectSeconds * 2 ** (failures - 1));
        retryAt = ctx.now() + wait;
        ctx.at(Math.min(retryAt, ctx.now() + 1), countdown);
      } else {
        retryAt = Infinity;
      }
      if (wasConnected) warns.warn(`lost the connection to rosbridge at ${url}: ${message}`);
      else if (failures === 1) warns.warn(`cannot connect to rosbridge at ${url}: ${message}`);
      describe();
    };

    const connect = (): void => {
      if (!bridge) return;
      const id = ++attempt;
      const current = (): boolean => id === attempt && running;
      state = "connecting";
      describe();
      const onState = (s: RosConnectionState, message?: string): void => {
        if (!current()) return;
        if (s === "connecting") {
          state = "connecting";
        } else if (s === "connected") {
          state = "connected";
          failures = 0;
          connections++;
          reason = "";
        } else {
          lost(message ?? "closed");
          return;
        }
        describe();
      };
      let c: RosConnection;
      try {
        c = bridge.connect({
          url,
          onState,
          onNotice: (m) => {
            if (current()) warns.warn(`rosbridge ${url} (${topic}): ${m}`);
          },
        });
      } catch (e) {
        lost(errorMessage(e));
        return;
      }
      if (!current() || (state as State) === "waiting") {
        // Refused at once (through onState): this attempt is over.
        try {
          c.close();
        } catch {
          // nothing to close
        }
        return;
      }
      conn = c;
      try {
        if (publish) {
          pub = c.advertise({
            topic,
            type,
            ...(p.Latch !== undefined ? { latch: p.Latch } : {}),
          });
        } else {
          sub = c.subscribe({
            topic,
            type,
            ...(p.ThrottleMs !== undefined ? { throttleMs: p.ThrottleMs } : {}),
            ...(p.QueueLength !== undefined ? { queueLength: p.QueueLength } : {}),
            onMessage,
          });
        }
      } catch (e) {
        if (current()) lost(errorMessage(e));
      }
    };

    return {
      start() {
        if (!bridge) {
          ctx.warn(
            "ROS is unavailable here (the browser build has no rosbridge connection): this block " +
              (publish ? "sends nothing" : "receives nothing"),
          );
          describe();
          return;
        }
        if (running) return;
        running = true;
        failures = 0;
        connect();
      },
      process(f) {
        const n = f.n;
        if (n === 0 || !encoder) return;
        const v = f.v;
        const stride = f.stride;
        const p0 = pub;
        const live = p0 !== undefined && state === "connected";
        for (let e = 0; e < n; e++) {
          const off = e * stride;
          if (!live) {
            dropped++;
            continue;
          }
          let finite = true;
          for (let k = 0; k < size; k++) {
            if (!Number.isFinite(v[off + k]!)) {
              finite = false;
              break;
            }
          }
          if (!finite) {
            skipped++;
            continue;
          }
          if (p0.publish(encoder.encode(v, off))) sent++;
          else dropped++;
        }
        if (throttle.due(f.t[n - 1]!)) describe();
      },
      stop() {
        running = false;
        attempt++;
        closeConnection();
        if (state !== "unavailable") state = "stopped";
        retryAt = Infinity;
        describe();
      },
      reset() {
        sent = 0;
        received = 0;
        dropped = 0;
        skipped = 0;
        malformed = 0;
        lastMalformed = "";
        connections = state === "connected" ? 1 : 0;
        throttle.reset();
        warns.reset();
        describe();
      },
      dispose() {
        running = false;
        attempt++;
        closeConnection();
      },
      actions: {
        counts: {
          label: "Counts",
          description:
            "Messages sent or received, dropped while disconnected, malformed, reconnects",
          run: () =>
            `${state}: ${sent} sent, ${received} received, ${dropped} dropped while disconnected, ` +
            `${skipped} not sent (NaN or ±∞), ${malformed} malformed` +
            `${lastMalformed ? ` (last: ${lastMalformed})` : ""}, ${Math.max(0, connections - 1)} reconnects`,
        },
      },
    };
  },
});
