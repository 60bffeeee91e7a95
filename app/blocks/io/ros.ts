import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  legacyInteger,
  LegacyParamsError,
  vectorShape,
  type BlockContext,
} from "../../engine";
import { signalInput } from "../shared/inputs";
import type { RosLinkOptions } from "./ros-link";
import { fixedSizeOf, ROS_MESSAGE_TYPES, rosDecoder, rosEncoder } from "./ros-messages";
import { RosRun, type RosSide } from "./ros-run";

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

/** Direction publish: the input's width, checked against the message type and Channels. */
function publishSide(ctx: BlockContext, p: Params): RosSide {
  const type = p.MessageType;
  const fixed = fixedSizeOf(type);
  if (ctx.inputs.length === 0) {
    throw new BlockConfigError(
      "Direction publish needs an input (the values to publish); to receive messages set Direction: subscribe",
      "Direction",
    );
  }
  const input = signalInput(ctx, 0);
  const size = input.size;
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
  const encoder = rosEncoder(type, {
    size,
    rows: input.shape.rows,
    cols: input.shape.cols,
    ...(p.JointNames ? { jointNames: p.JointNames } : {}),
  });
  return { publish: true, size, encoder };
}

/** Direction subscribe: the width of the output from Channels, the message type or JointNames. */
function subscribeSide(ctx: BlockContext, p: Params): RosSide {
  const type = p.MessageType;
  const fixed = fixedSizeOf(type);
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
  const size = p.Channels ?? fixed ?? p.JointNames?.length;
  if (size === undefined) {
    throw new BlockConfigError(
      `Channels is needed to subscribe to ${type} (the values per message: the width of the output)`,
      "Channels",
    );
  }
  const decoder = rosDecoder(type, {
    size,
    ...(p.JointNames ? { jointNames: p.JointNames } : {}),
  });
  return { publish: false, size, decoder, out: ctx.output(vectorShape(size)) };
}

function linkOptions(p: Params): RosLinkOptions {
  return {
    url: p.Url,
    topic: p.Topic,
    type: p.MessageType,
    publish: p.Direction === "publish",
    latch: p.Latch,
    throttleMs: p.ThrottleMs,
    queueLength: p.QueueLength,
    reconnectSeconds: p.ReconnectSeconds,
    reconnectMaxSeconds: p.ReconnectMaxSeconds,
  };
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
    const side = p.Direction === "publish" ? publishSide(ctx, p) : subscribeSide(ctx, p);
    if (p.JointNames !== undefined && p.JointNames.length !== side.size) {
      throw new BlockConfigError(
        `JointNames lists ${p.JointNames.length} joints for ${side.size} values: give one name per value`,
        "JointNames",
      );
    }
    return new RosRun(ctx, side, linkOptions(p)).instance();
  },
});
