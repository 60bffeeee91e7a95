/**
 * The structure of a kinematic chain (the BodyRig block's `Links`): what is wrong with it, as
 * messages naming the link and the key, and the order in which its links can be computed
 * (every parent before its children).
 */
import { closest } from "../../engine";
import { MIN_QUATERNION_NORM } from "./quaternion";

/** The name of the chain's base point (Origin) in the output's channel names. */
export const BASE_NAME = "base";

/** One link as written in Params (before the block resolves inputs and channels). */
export interface LinkSpec {
  readonly Name: string;
  readonly Parent?: string | undefined;
  readonly Length?: number | undefined;
  readonly Offset?: readonly number[] | undefined;
  readonly Axis?: string | undefined;
  readonly SensorToSegment?: readonly number[] | undefined;
  readonly SensorToSegmentEuler?: readonly number[] | undefined;
  readonly Input?: string | undefined;
  readonly Channel?: number | undefined;
}

/** A problem found in `Links`, at `Links[index].key`. */
export interface ChainIssue {
  readonly index: number;
  readonly key: keyof LinkSpec;
  readonly message: string;
}

/** Index of each name's first link. */
function nameIndex(links: readonly LinkSpec[]): Map<string, number> {
  const m = new Map<string, number>();
  links.forEach((l, i) => {
    if (!m.has(l.Name)) m.set(l.Name, i);
  });
  return m;
}

function nameIssues(links: readonly LinkSpec[], byName: Map<string, number>): ChainIssue[] {
  const out: ChainIssue[] = [];
  links.forEach((l, i) => {
    if (l.Name === BASE_NAME) {
      out.push({
        index: i,
        key: "Name",
        message: `link name '${BASE_NAME}' is reserved for the chain's Origin in the output's channel names`,
      });
    }
    const first = byName.get(l.Name)!;
    if (first !== i) {
      out.push({
        index: i,
        key: "Name",
        message: `link '${l.Name}' is defined twice (Links[${first}] and Links[${i}]); names must be unique`,
      });
    }
  });
  return out;
}

function parentIssues(links: readonly LinkSpec[], byName: Map<string, number>): ChainIssue[] {
  const out: ChainIssue[] = [];
  links.forEach((l, i) => {
    if (l.Parent === undefined) return;
    if (l.Parent === l.Name) {
      out.push({ index: i, key: "Parent", message: `link '${l.Name}' is its own parent` });
    } else if (!byName.has(l.Parent)) {
      const hint = closest(l.Parent, byName.keys());
      out.push({
        index: i,
        key: "Parent",
        message:
          `link '${l.Name}': parent '${l.Parent}' is not a link of this chain` +
          (hint !== undefined ? `; did you mean '${hint}'?` : "") +
          " (leave Parent out for a root link, which starts at Origin)",
      });
    }
  });
  return out;
}

/** Index of each link's parent; -1 for roots and for parents that do not resolve. */
export function parentIndices(links: readonly LinkSpec[]): Int32Array {
  const byName = nameIndex(links);
  const parents = new Int32Array(links.length).fill(-1);
  links.forEach((l, i) => {
    const p = l.Parent === undefined ? undefined : byName.get(l.Parent);
    if (p !== undefined && p !== i) parents[i] = p;
  });
  return parents;
}

/** Cycles of parents, reported once each, at the cycle's first link in `Links`. */
function cycleIssues(links: readonly LinkSpec[]): ChainIssue[] {
  const parents = parentIndices(links);
  const out: ChainIssue[] = [];
  const n = links.length;
  for (let i = 0; i < n; i++) {
    const path = [i];
    let j = parents[i]!;
    while (j >= 0 && j !== i && path.length <= n) {
      path.push(j);
      j = parents[j]!;
    }
    if (j !== i) continue;
    if (Math.min(...path) !== i) continue;
    const names = [...path, i].map((k) => `'${links[k]!.Name}'`).join(" → ");
    out.push({
      index: i,
      key: "Parent",
      message: `link '${links[i]!.Name}' is its own ancestor (${names}); a chain needs a root link without Parent`,
    });
  }
  return out;
}

function shapeIssues(links: readonly LinkSpec[]): ChainIssue[] {
  const out: ChainIssue[] = [];
  links.forEach((l, i) => {
    const at = `link '${l.Name}'`;
    if (l.Length === undefined && l.Offset === undefined) {
      out.push({
        index: i,
        key: "Length",
        message: `${at} needs Length (m, along Axis) or Offset ([x, y, z] m in the segment's frame)`,
      });
    }
    if (l.Length !== undefined && l.Offset !== undefined) {
      out.push({
        index: i,
        key: "Offset",
        message: `${at} has both Length and Offset; give one (Offset is the whole vector)`,
      });
    }
    if (l.Axis !== undefined && l.Offset !== undefined) {
      out.push({
        index: i,
        key: "Axis",
        message: `${at}: Axis applies to Length, not to Offset (which gives the direction itself)`,
      });
    }
    if (l.SensorToSegment !== undefined && l.SensorToSegmentEuler !== undefined) {
      out.push({
        index: i,
        key: "SensorToSegmentEuler",
        message: `${at} has both SensorToSegment (quaternion) and SensorToSegmentEuler; give one`,
      });
    }
    const q = l.SensorToSegment;
    if (q !== undefined && Math.hypot(...q) < MIN_QUATERNION_NORM) {
      out.push({
        index: i,
        key: "SensorToSegment",
        message: `${at}: SensorToSegment [${q.join(", ")}] has zero norm; it is no rotation (identity: [1, 0, 0, 0])`,
      });
    }
  });
  return out;
}

/** Everything wrong with the chain's structure; empty when it is a forest of trees. */
export function chainIssues(links: readonly LinkSpec[]): ChainIssue[] {
  const byName = nameIndex(links);
  return [
    ...nameIssues(links, byName),
    ...parentIssues(links, byName),
    ...cycleIssues(links),
    ...shapeIssues(links),
  ];
}

/**
 * Link indices with every parent before its children: by depth (steps to the root), then by
 * position in `Links`. A parent is one step nearer the root than its child, hence before it.
 */
export function computeOrder(parents: Int32Array): Int32Array {
  const n = parents.length;
  const depth = new Int32Array(n);
  for (let i = 0; i < n; i++) {
    let d = 0;
    let j = parents[i]!;
    while (j >= 0 && d < n) {
      d++;
      j = parents[j]!;
    }
    depth[i] = d;
  }
  const indices = Array.from({ length: n }, (_, i) => i);
  indices.sort((a, b) => depth[a]! - depth[b]! || a - b);
  return Int32Array.from(indices);
}
