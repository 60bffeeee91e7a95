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

/** Fingers folded into the palm: knuckles on top, the finger ends across the palm. */
function Folded({ skip = -1 }: { skip?: number }) {
  return (
    <g>
      {BASES.map((x, i) =>
        i === skip ? null : <rect key={x} x={x - 12} y={96} width={24} height={36} rx={12} />,
      )}
      <path d="M58 150 H142 M58 172 H142" className="gesture-svg__line" />
    </g>
  );
}

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
      <Palm />
      <Folded />
      {thumbUp ? (
        <Finger x={54} y={150} len={62} angle={-6} width={26} />
      ) : (
        <rect x={46} y={128} width={84} height={26} rx={13} />
      )}
    </g>
  );
}

function Pinch() {
  return (
    <g>
      <Forearm />
      {BASES.slice(1).map((x, i) => (
        <Finger key={x} x={x} y={124} len={LENGTHS[i + 1]!} angle={[2, 6, 12][i]!} />
      ))}
      <Finger x={62} y={124} len={52} angle={-38} />
      <Finger x={54} y={168} len={70} angle={-14} width={26} />
      <Palm />
      <circle cx={34} cy={86} r={9} className="gesture-svg__touch" />
    </g>
  );
}

function Point() {
  return (
    <g>
      <Forearm />
      <Finger x={62} y={124} len={70} />
      <Palm />
      <Folded skip={0} />
      <rect x={46} y={128} width={84} height={26} rx={13} />
    </g>
  );
}

/** A curved arrow along an arc, its head at the end. */
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
  const angle = down ? 48 : -48;
  return (
    <g>
      <rect x={6} y={140} width={104} height={44} rx={14} />
      <g className="gesture-svg__ghost">
        <rect x={100} y={142} width={92} height={40} rx={20} />
      </g>
      <g transform={`rotate(${angle} 104 162)`}>
        <rect x={100} y={142} width={92} height={40} rx={20} />
        <rect x={112} y={132} width={34} height={16} rx={8} />
      </g>
      {down ? (
        <Arrow d="M176 126 A74 74 0 0 1 160 218" head="M148 206 L160 222 L170 204" />
      ) : (
        <Arrow d="M176 198 A74 74 0 0 0 160 106" head="M148 118 L160 102 L170 120" />
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
        <span>{label}</span>
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
