/**
 * The items of a block's actions menu (BlockMenu), in order: the control panel, the block's own
 * actions (an EmgSimulator's setGesture as one item per gesture), then subscribe/unsubscribe for
 * each input. A separator comes before the first action and before the first input.
 */
import type { ActionInfo, BlockInfo } from "../../engine/protocol";
import { gestureNames } from "../app/gesture-names";

export interface MenuItem {
  label: string;
  hint?: string;
  run(): void;
  separatorBefore?: boolean;
}

/** Runs a block action: its name, argument, and the label to report it by. */
export type Invoke = (action: string, arg: unknown, label: string) => void;

type Item = Omit<MenuItem, "separatorBefore">;

const BUILT_IN_INPUT_ACTIONS = new Set(["subscribe", "unsubscribe"]);

/** All the items; `subscribed[i]` is "true" when input i is subscribed. */
export function menuItems(
  block: BlockInfo,
  subscribed: readonly string[],
  panelOpen: boolean,
  onTogglePanel: () => void,
  onInvoke: Invoke,
): MenuItem[] {
  return [
    panelItem(panelOpen, onTogglePanel),
    ...group(actionItems(block, onInvoke)),
    ...group(inputItems(block, subscribed, onInvoke)),
  ];
}

/** The first item of a group has a separator before it, the others none. */
function group(items: Item[]): MenuItem[] {
  return items.map((it, i) => ({ ...it, separatorBefore: i === 0 }));
}

function panelItem(panelOpen: boolean, onTogglePanel: () => void): MenuItem {
  return {
    label: panelOpen ? "Close control panel" : "Open control panel",
    hint: "Enter",
    run: onTogglePanel,
  };
}

/** The block's own actions, less subscribe/unsubscribe (one item per input instead). */
function actionItems(block: BlockInfo, onInvoke: Invoke): Item[] {
  const items: Item[] = [];
  for (const a of block.actions) {
    if (BUILT_IN_INPUT_ACTIONS.has(a.name)) continue;
    if (block.type === "EmgSimulator" && a.name === "setGesture")
      items.push(...gestureItems(block, onInvoke));
    else items.push(actionItem(a, onInvoke));
  }
  return items;
}

function actionItem(a: ActionInfo, onInvoke: Invoke): Item {
  return {
    label: a.label,
    ...(a.description !== undefined ? { hint: a.description } : {}),
    run: () => onInvoke(a.name, undefined, a.label),
  };
}

/** One item per gesture, the first nine with their key (1–9) as the hint. */
function gestureItems(block: BlockInfo, onInvoke: Invoke): Item[] {
  return gestureNames(block).map((g, i) => ({
    label: `Gesture: ${g}`,
    ...(i < 9 ? { hint: `key ${i + 1}` } : {}),
    run: () => onInvoke("setGesture", g, `Gesture: ${g}`),
  }));
}

function inputItems(block: BlockInfo, subscribed: readonly string[], onInvoke: Invoke): Item[] {
  return block.inputs.map((inp, i) => {
    const on = subscribed[i] === "true";
    const label = `${on ? "Unsubscribe" : "Subscribe"} input ${inp.source}`;
    return { label, run: () => onInvoke(on ? "unsubscribe" : "subscribe", i, label) };
  });
}
