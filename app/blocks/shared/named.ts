/**
 * State a block offers to the other blocks of its pipeline by its name, for what the original
 * MOSAIC did by name rather than by wiring: its BatchPredictor and PythonNetLearning read the
 * clusters of a Buffer named in their Params when their model was built. Edges stay the way to
 * move data; this is for a block that pulls another's state on request (a "build model" action),
 * as the original did.
 *
 * Entries live per pipeline instance (keyed by the runtime's `resources`, one per loaded
 * pipeline) and per worker: a block on another worker (`Worker:`) is not found, and the caller
 * says so. A block publishes at create and withdraws at dispose.
 */
import type { BlockContext } from "../../engine";

const registry = new WeakMap<object, Map<string, { kind: string; value: unknown }>>();

function entries(ctx: BlockContext): Map<string, { kind: string; value: unknown }> {
  let m = registry.get(ctx.resources);
  if (!m) registry.set(ctx.resources, (m = new Map()));
  return m;
}

/** Offers `value` as `kind` under this block's name; returns the function that withdraws it. */
export function publish(ctx: BlockContext, kind: string, value: unknown): () => void {
  const m = entries(ctx);
  const entry = { kind, value };
  m.set(ctx.name, entry);
  return () => {
    if (m.get(ctx.name) === entry) m.delete(ctx.name);
  };
}

/**
 * What block `name` offers as `kind`: the value, or a sentence saying why there is none (no such
 * block on this worker, or a block of another kind).
 */
export function lookup<T>(ctx: BlockContext, name: string, kind: string): T | string {
  const e = entries(ctx).get(name);
  if (e === undefined) {
    return (
      `there is no ${kind} '${name}' in this pipeline on this worker (a block on another ` +
      "Worker cannot be read by name)"
    );
  }
  if (e.kind !== kind) return `'${name}' is not a ${kind}`;
  return e.value as T;
}
