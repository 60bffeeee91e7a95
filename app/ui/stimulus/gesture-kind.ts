/**
 * Which drawing shows a gesture, from its label as a pipeline names it ("fist", "Hand close",
 * "wrist_flexion", "tripod"): exact names and common synonyms first, then parts of words. A name
 * that matches none has no drawing: the participant screen writes it out instead.
 */
export const GESTURE_KINDS = [
  "rest",
  "fist",
  "open",
  "pinch",
  "point",
  "thumb",
  "flexion",
  "extension",
  "pronation",
  "supination",
] as const;
export type GestureKind = (typeof GESTURE_KINDS)[number];

const SYNONYMS: Record<string, GestureKind> = {
  rest: "rest",
  relax: "rest",
  relaxed: "rest",
  neutral: "rest",
  idle: "rest",
  none: "rest",
  fist: "fist",
  close: "fist",
  closed: "fist",
  handclose: "fist",
  closehand: "fist",
  grasp: "fist",
  power: "fist",
  powergrasp: "fist",
  cylinder: "fist",
  cylindrical: "fist",
  open: "open",
  handopen: "open",
  openhand: "open",
  spread: "open",
  pinch: "pinch",
  precision: "pinch",
  tip: "pinch",
  tippinch: "pinch",
  tripod: "pinch",
  key: "pinch",
  keypinch: "pinch",
  lateral: "pinch",
  lateralpinch: "pinch",
  point: "point",
  pointing: "point",
  index: "point",
  indexpoint: "point",
  thumb: "thumb",
  thumbup: "thumb",
  thumbsup: "thumb",
  flexion: "flexion",
  flex: "flexion",
  wristflexion: "flexion",
  extension: "extension",
  extend: "extension",
  wristextension: "extension",
  pronation: "pronation",
  pronate: "pronation",
  wristpronation: "pronation",
  supination: "supination",
  supinate: "supination",
  wristsupination: "supination",
};

/** Parts of words, tried in order when the whole name is not known. */
const PARTS: [string, GestureKind][] = [
  ["flex", "flexion"],
  ["exten", "extension"],
  ["pron", "pronation"],
  ["supin", "supination"],
  ["pinch", "pinch"],
  ["tripod", "pinch"],
  ["point", "point"],
  ["thumb", "thumb"],
  ["fist", "fist"],
  ["grasp", "fist"],
  ["close", "fist"],
  ["open", "open"],
  ["rest", "rest"],
  ["relax", "rest"],
];

/** The drawing for a gesture label; undefined when there is none (its name is shown). */
export function gestureKind(label: string): GestureKind | undefined {
  const key = label.toLowerCase().replace(/[^a-z]/g, "");
  if (key === "") return undefined;
  return SYNONYMS[key] ?? PARTS.find(([part]) => key.includes(part))?.[1];
}
