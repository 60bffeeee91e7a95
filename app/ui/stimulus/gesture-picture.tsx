/**
 * Simple, clear drawings of hand and wrist gestures for the participant screen (a right hand,
 * palm towards the viewer; the wrist movements from the side), one per gesture kind
 * (gesture-kind.ts). A label without a drawing is written out in large type instead.
 */
import type { ReactElement } from "react";
import { gestureKind, type GestureKind } from "./gesture-kind";

/** A finger (or thumb): a capsule from its base (x, y) upwards, turned by `angle` degrees. */
function Finger({
  x,
  y,
  len,
  angle = 0,
  width = 24,
}: {
  x: number;
  y: number;
  len: number;
  angle?: number;
  width?: number;
}) {
  return (
    <rect
      x={x - width / 2}
      y={y - len}
      width={width}
      height={len + width / 2}
      rx={width / 2}
      transform={angle !== 0 ? `rotate(${angle} ${x} ${y})` : undefined}
    />
  );
}

/** Finger bases (index … little) on the palm's top edge. */
const BASES = [62, 88, 113, 137] as const;
const LENGTHS = [64, 74, 68, 54] as const;

const Palm = () => <rect x={48} y={108} width={104} height={104} rx={30} />;
const Forearm = () => <rect x={68} y={196} width={64} height={70} rx={10} />;

/** The knuckles of fingers folded into the palm (drawn behind it: only their tops show). */
function Knuckles({ skip = -1 }: { skip?: number }) {
  return (
    <g>
      {BASES.map((x, i) =>
        i === skip ? null : <rect key={x} x={x - 12} y={92} width={24} height={40} rx={12} />,
      )}
    </g>
  );
}

/** The folded fingers' ends across the palm. */
const FoldLines = () => <path d="M58 150 H142 M58 172 H142" className="gesture-svg__line" />;

function OpenHand({ spread, relaxed = false }: { spread: boolean; relaxed?: boolean }) {
  const angles = spread ? [-14, -4, 5, 15] : [-3, -1, 1, 3];
  const shorten = relaxed ? 6 : 0;
  return (
    <g>
      <Forearm />
      {BASES.map((x, i) => (
        <Finger key={x} x={x} y={124} len={LENGTHS[i]! - shorten} angle={angles[i]!} />
      ))}
      <Finger x={58} y={178} len={56} angle={spread ? -52 : -22} width={26} />
      <Palm />
    </g>
  );
}

function Fist({ thumbUp = false }: { thumbUp?: boolean }) {
  return (
    <g>
      <Forearm />
      <Knuckles />
      <Palm />
      <FoldLines />
      {thumbUp ? (
        <Finger x={54} y={150} len={62} angle={-6} width={26} />
      ) : (
        <rect x={46} y={128} width={84} height={26} rx={13} />
      )}
    </g>
  );
}

/** A bent finger or thumb along a path: an outlined band (two strokes). */
function Bent({ d }: { d: string }) {
  return (
    <g className="gesture-svg__bent">
      <path d={d} className="gesture-svg__bent-outline" />
      <path d={d} className="gesture-svg__bent-fill" />
    </g>
  );
}

/** Thumb and index tips touching in a ring, the other fingers straight. */
function Pinch() {
  return (
    <g transform="translate(22 0)">
      <Forearm />
      {BASES.slice(1).map((x, i) => (
        <Finger key={x} x={x} y={124} len={LENGTHS[i + 1]!} angle={[2, 6, 12][i]!} />
      ))}
      <Bent d="M62 128 C62 44 -6 40 2 94" />
      <Bent d="M60 190 C16 190 -8 140 4 108" />
      <Palm />
    </g>
  );
}

function Point() {
  return (
    <g>
      <Forearm />
      <Finger x={62} y={124} len={70} />
      <Knuckles skip={0} />
      <Palm />
      <FoldLines />
      <rect x={46} y={128} width={84} height={26} rx={13} />
    </g>
  );
}

/** A point at `deg` degrees (clockwise from +x, as on screen) on a circle. */
const onCircle = (cx: number, cy: number, r: number, deg: number): [number, number] => {
  const a = (deg * Math.PI) / 180;
  return [cx + r * Math.cos(a), cy + r * Math.sin(a)];
};
const xy = ([x, y]: [number, number]): string => `${x.toFixed(1)} ${y.toFixed(1)}`;

/** A curved arrow along a circle from `from` to `to` degrees, its head at `to`. */
function ArcArrow({
  cx,
  cy,
  r,
  from,
  to,
}: {
  cx: number;
  cy: number;
  r: number;
  from: number;
  to: number;
}) {
  const clockwise = to > from;
  const end = onCircle(cx, cy, r, to);
  // Two short strokes back from the end, on either side of the circle.
  const back = clockwise ? -14 : 14;
  const d = `M${xy(onCircle(cx, cy, r, from))} A${r} ${r} 0 0 ${clockwise ? 1 : 0} ${xy(end)}`;
  const head = `M${xy(onCircle(cx, cy, r - 12, to + back))} L${xy(end)} L${xy(onCircle(cx, cy, r + 12, to + back))}`;
  return (
    <g className="gesture-svg__arrow">
      <path d={d} />
      <path d={head} />
    </g>
  );
}

/** An arrow along any path, with its head drawn by `head`. */
function Arrow({ d, head }: { d: string; head: string }) {
  return (
    <g className="gesture-svg__arrow">
      <path d={d} />
      <path d={head} className="gesture-svg__head" />
    </g>
  );
}

/** The wrist from the side: forearm level, the hand bent down (flexion) or up (extension). */
function Wrist({ down }: { down: boolean }) {
  const angle = down ? 50 : -50;
  return (
    <g>
      <rect x={-4} y={132} width={80} height={40} rx={14} />
      <g className="gesture-svg__ghost">
        <rect x={66} y={132} width={92} height={40} rx={20} />
      </g>
      <g transform={`rotate(${angle} 70 152)`}>
        <rect x={66} y={132} width={92} height={40} rx={20} />
        <rect x={78} y={122} width={34} height={16} rx={8} />
      </g>
      {down ? (
        <ArcArrow cx={70} cy={152} r={116} from={-6} to={58} />
      ) : (
        <ArcArrow cx={70} cy={152} r={116} from={6} to={-58} />
      )}
    </g>
  );
}

/** The hand turning about the forearm: pronation (palm down) or supination (palm up). */
function Turn({ inward }: { inward: boolean }) {
  return (
    <g>
      <OpenHand spread={false} relaxed />
      {inward ? (
        <Arrow d="M40 236 A64 22 0 1 0 160 236" head="M148 226 L162 238 L146 248" />
      ) : (
        <Arrow d="M160 236 A64 22 0 1 1 40 236" head="M52 226 L38 238 L54 248" />
      )}
    </g>
  );
}

const DRAWINGS: Record<GestureKind, () => ReactElement> = {
  rest: () => <OpenHand spread={false} relaxed />,
  open: () => <OpenHand spread />,
  fist: () => <Fist />,
  thumb: () => <Fist thumbUp />,
  pinch: () => <Pinch />,
  point: () => <Point />,
  flexion: () => <Wrist down />,
  extension: () => <Wrist down={false} />,
  pronation: () => <Turn inward />,
  supination: () => <Turn inward={false} />,
};

/** Type size (vmin) that fits a label's longest word in the box. */
function textSize(label: string, size: "large" | "small"): number {
  const longest = Math.max(1, ...label.split(/\s+/).map((w) => w.length));
  const box = size === "large" ? 40 : 15;
  return Math.min(size === "large" ? 9 : 3.5, (box / longest) * 1.6);
}

/** The drawing of `label`, or the label in large type when there is none. */
export function GesturePicture({
  label,
  size = "large",
}: {
  label: string;
  size?: "large" | "small";
}) {
  const kind = gestureKind(label);
  if (kind === undefined) {
    return (
      <div
        className={`gesture-picture gesture-picture--${size} gesture-picture--text`}
        data-kind="text"
      >
        <span style={{ fontSize: `${textSize(label, size)}vmin` }}>{label}</span>
      </div>
    );
  }
  return (
    <div className={`gesture-picture gesture-picture--${size}`} data-kind={kind}>
      <svg
        viewBox="0 0 200 270"
        role="img"
        aria-label={`${label} (${kind})`}
        className={`gesture-svg gesture-svg--${kind}`}
      >
        {DRAWINGS[kind]()}
      </svg>
    </div>
  );
}
