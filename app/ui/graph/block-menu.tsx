/**
 * A block's actions (right-click, Shift+F10 or the ⋮ button on a node): the block's own actions
 * from BlockInfo.actions (start/stop timer, train, reset, save buffer…), subscribe/unsubscribe for
 * each of its inputs, and its control panel. A menu in the WAI-ARIA sense: arrow keys move, Enter
 * runs, Escape closes and gives the focus back.
 */
import { useEffect, useLayoutEffect, useRef, useState } from "react";
import type { BlockInfo } from "../../engine/protocol";
import { useTelemetrySelector } from "../client/hooks";
import { gestureNames } from "../app/gesture-names";

export interface MenuItem {
  label: string;
  hint?: string;
  run(): void;
  separatorBefore?: boolean;
}

interface Props {
  block: BlockInfo;
  anchor: { x: number; y: number };
  panelOpen: boolean;
  onClose(): void;
  onTogglePanel(): void;
  onInvoke(action: string, arg: unknown, label: string): void;
}

const BUILT_IN_INPUT_ACTIONS = new Set(["subscribe", "unsubscribe"]);

export function BlockMenu({ block, anchor, panelOpen, onClose, onTogglePanel, onInvoke }: Props) {
  const subscribed = useTelemetrySelector(
    (t) =>
      block.inputs
        .map((inp, i) => {
          const e = t?.edges.find((x) => x.to === block.name && x.toIndex === i);
          return e ? e.subscribed : inp.subscribed;
        })
        .join(","),
    Object.is,
  ).split(",");

  const items: MenuItem[] = [
    {
      label: panelOpen ? "Close control panel" : "Open control panel",
      hint: "Enter",
      run: onTogglePanel,
    },
  ];
  let first = true;
  for (const a of block.actions) {
    if (BUILT_IN_INPUT_ACTIONS.has(a.name)) continue;
    if (block.type === "EmgSimulator" && a.name === "setGesture") {
      gestureNames(block).forEach((g, i) => {
        items.push({
          label: `Gesture: ${g}`,
          ...(i < 9 ? { hint: `key ${i + 1}` } : {}),
          run: () => onInvoke("setGesture", g, `Gesture: ${g}`),
          separatorBefore: first && i === 0,
        });
        first = false;
      });
      continue;
    }
    items.push({
      label: a.label,
      ...(a.description !== undefined ? { hint: a.description } : {}),
      run: () => onInvoke(a.name, undefined, a.label),
      separatorBefore: first,
    });
    first = false;
  }
  block.inputs.forEach((inp, i) => {
    const on = subscribed[i] === "true";
    const label = `${on ? "Unsubscribe" : "Subscribe"} input ${inp.source}`;
    items.push({
      label,
      run: () => onInvoke(on ? "unsubscribe" : "subscribe", i, label),
      separatorBefore: i === 0,
    });
  });

  const ref = useRef<HTMLDivElement>(null);
  const [active, setActive] = useState(0);
  const [pos, setPos] = useState(anchor);

  // Keep the menu inside the window.
  useLayoutEffect(() => {
    const el = ref.current;
    if (!el) return;
    const r = el.getBoundingClientRect();
    const x = Math.max(4, Math.min(anchor.x, window.innerWidth - r.width - 4));
    const y = Math.max(4, Math.min(anchor.y, window.innerHeight - r.height - 4));
    setPos({ x, y });
  }, [anchor.x, anchor.y]);

  useEffect(() => {
    const el = ref.current?.querySelectorAll<HTMLElement>("[role=menuitem]")[active];
    el?.focus();
  }, [active]);

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

  const onKeyDown = (e: React.KeyboardEvent): void => {
    const n = items.length;
    if (e.key === "ArrowDown") setActive((a) => (a + 1) % n);
    else if (e.key === "ArrowUp") setActive((a) => (a - 1 + n) % n);
    else if (e.key === "Home") setActive(0);
    else if (e.key === "End") setActive(n - 1);
    else if (e.key === "Escape" || e.key === "Tab") onClose();
    else return;
    e.preventDefault();
    e.stopPropagation();
  };

  return (
    <div
      ref={ref}
      className="block-menu"
      role="menu"
      aria-label={`Actions of ${block.name}`}
      data-menu={block.name}
      style={{ left: pos.x, top: pos.y }}
      onKeyDown={onKeyDown}
      onContextMenu={(e) => e.preventDefault()}
    >
      <div className="block-menu__title" aria-hidden="true">
        {block.name} <span>{block.type}</span>
      </div>
      {items.map((it, i) => (
        <div key={`${i}:${it.label}`} role="none">
          {it.separatorBefore ? <div className="block-menu__sep" role="separator" /> : null}
          <button
            type="button"
            role="menuitem"
            tabIndex={i === active ? 0 : -1}
            className="block-menu__item"
            title={it.hint}
            onMouseEnter={() => setActive(i)}
            onClick={() => {
              onClose();
              it.run();
            }}
          >
            <span>{it.label}</span>
            {it.hint && it.hint.length <= 8 ? <kbd>{it.hint}</kbd> : null}
          </button>
        </div>
      ))}
    </div>
  );
}
