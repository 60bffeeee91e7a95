/**
 * A block's actions (right-click, Shift+F10 or the ⋮ button on a node): the block's own actions
 * from BlockInfo.actions (start/stop timer, train, reset, save buffer…), subscribe/unsubscribe for
 * each of its inputs, and its control panel. A menu in the WAI-ARIA sense: arrow keys move, Enter
 * runs, Escape closes and gives the focus back.
 */
import {
  useEffect,
  useLayoutEffect,
  useRef,
  useState,
  type Dispatch,
  type RefObject,
  type SetStateAction,
} from "react";
import type { BlockInfo } from "../../engine/protocol";
import { useTelemetrySelector } from "../client/hooks";
import { menuItems, type MenuItem } from "./block-menu-items";

export type { MenuItem } from "./block-menu-items";

interface Props {
  block: BlockInfo;
  anchor: { x: number; y: number };
  panelOpen: boolean;
  onClose(): void;
  onTogglePanel(): void;
  onInvoke(action: string, arg: unknown, label: string): void;
}

type Point = { x: number; y: number };
type MenuRef = RefObject<HTMLDivElement | null>;

export function BlockMenu({ block, anchor, panelOpen, onClose, onTogglePanel, onInvoke }: Props) {
  const subscribed = useSubscribedInputs(block);
  const items = menuItems(block, subscribed, panelOpen, onTogglePanel, onInvoke);
  const ref = useRef<HTMLDivElement>(null);
  const [active, setActive] = useState(0);
  const pos = useInsideWindow(ref, anchor);
  useFocusItem(ref, active);
  useCloseWhenAway(ref, onClose);
  return (
    <div
      ref={ref}
      className="block-menu"
      role="menu"
      aria-label={`Actions of ${block.name}`}
      data-menu={block.name}
      style={{ left: pos.x, top: pos.y }}
      onKeyDown={menuKeys(items.length, setActive, onClose)}
      onContextMenu={(e) => e.preventDefault()}
    >
      <div className="block-menu__title" aria-hidden="true">
        {block.name} <span>{block.type}</span>
      </div>
      {items.map((it, i) => (
        <BlockMenuItem
          key={`${i}:${it.label}`}
          item={it}
          focusable={i === active}
          onHover={() => setActive(i)}
          onClose={onClose}
        />
      ))}
    </div>
  );
}

/** One item: a separator before it if it starts a group, and its key (a short hint) on the right. */
function BlockMenuItem({
  item,
  focusable,
  onHover,
  onClose,
}: {
  item: MenuItem;
  focusable: boolean;
  onHover(): void;
  onClose(): void;
}) {
  return (
    <div role="none">
      {item.separatorBefore ? <div className="block-menu__sep" role="separator" /> : null}
      <button
        type="button"
        role="menuitem"
        tabIndex={focusable ? 0 : -1}
        className="block-menu__item"
        title={item.hint}
        onMouseEnter={onHover}
        onClick={() => {
          onClose();
          item.run();
        }}
      >
        <span>{item.label}</span>
        {item.hint && item.hint.length <= 8 ? <kbd>{item.hint}</kbd> : null}
      </button>
    </div>
  );
}

/** "true" or "false" per input: the live edge's state, else the graph's. */
function useSubscribedInputs(block: BlockInfo): string[] {
  return useTelemetrySelector(
    (t) =>
      block.inputs
        .map((inp, i) => {
          const e = t?.edges.find((x) => x.to === block.name && x.toIndex === i);
          return e ? e.subscribed : inp.subscribed;
        })
        .join(","),
    Object.is,
  ).split(",");
}

/** The menu's position: at the anchor, moved to keep the menu inside the window. */
function useInsideWindow(ref: MenuRef, anchor: Point): Point {
  const [pos, setPos] = useState(anchor);
  useLayoutEffect(() => {
    const el = ref.current;
    if (!el) return;
    const r = el.getBoundingClientRect();
    const x = Math.max(4, Math.min(anchor.x, window.innerWidth - r.width - 4));
    const y = Math.max(4, Math.min(anchor.y, window.innerHeight - r.height - 4));
    setPos({ x, y });
  }, [anchor.x, anchor.y]);
  return pos;
}

/** The focus follows the active item. */
function useFocusItem(ref: MenuRef, active: number): void {
  useEffect(() => {
    const el = ref.current?.querySelectorAll<HTMLElement>("[role=menuitem]")[active];
    el?.focus();
  }, [active]);
}

/** A pointer down outside the menu, or the window losing the focus, closes it. */
function useCloseWhenAway(ref: MenuRef, onClose: () => void): void {
  useEffect(() => {
    const away = (e: PointerEvent): void => {
      if (ref.current && !ref.current.contains(e.target as Node)) onClose();
    };
    const blur = (): void => onClose();
    window.addEventListener("pointerdown", away, true);
    window.addEventListener("blur", blur);
    return () => {
      window.removeEventListener("pointerdown", away, true);
      window.removeEventListener("blur", blur);
    };
  }, [onClose]);
}

/** Arrows, Home and End move among the `n` items; Escape and Tab close the menu. */
function menuKeys(n: number, setActive: Dispatch<SetStateAction<number>>, onClose: () => void) {
  return (e: React.KeyboardEvent): void => {
    if (e.key === "ArrowDown") setActive((a) => (a + 1) % n);
    else if (e.key === "ArrowUp") setActive((a) => (a - 1 + n) % n);
    else if (e.key === "Home") setActive(0);
    else if (e.key === "End") setActive(n - 1);
    else if (e.key === "Escape" || e.key === "Tab") onClose();
    else return;
    e.preventDefault();
    e.stopPropagation();
  };
}
