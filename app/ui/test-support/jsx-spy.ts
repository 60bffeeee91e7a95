/**
 * For component tests rendered with react-dom/server (there is no DOM here): React's JSX runtime
 * wrapped so that a test sees every element created while it renders, with its props, and can
 * call the handlers a DOM would. In the test file (vi.mock is hoisted above the imports):
 *
 *   vi.mock("react/jsx-runtime", async (orig) =>
 *     (await import("../test-support/jsx-spy")).spyJsx(await orig()));
 *   vi.mock("react/jsx-dev-runtime", async (orig) =>
 *     (await import("../test-support/jsx-spy")).spyJsx(await orig()));
 *
 * and `created.length = 0` after each test.
 */

/** One element as created: a tag name or a component, and its props. */
export interface Created {
  type: unknown;
  props: Record<string, unknown>;
}

/** Every element created since the list was last emptied, in order. */
export const created: Created[] = [];

type Jsx = (type: unknown, props: Record<string, unknown>, ...rest: unknown[]) => unknown;

const recording =
  (jsx: Jsx): Jsx =>
  (type, props, ...rest) => {
    created.push({ type, props });
    return jsx(type, props, ...rest);
  };

/** The JSX runtime module `m` with its element factories (jsx, jsxs, jsxDEV) recording. */
export function spyJsx<M extends object>(m: M): M {
  const out = { ...m } as Record<string, unknown>;
  for (const k of ["jsx", "jsxs", "jsxDEV"]) {
    if (typeof out[k] === "function") out[k] = recording(out[k] as Jsx);
  }
  return out as M;
}

/** The props of the DOM elements created with the handler `name` ("onClick"), in order. */
export function withHandler<K extends string>(name: K): Record<K, (e: unknown) => void>[] {
  return created
    .filter((c) => typeof c.type === "string" && c.props[name] !== undefined)
    .map((c) => c.props as Record<K, (e: unknown) => void>);
}

/** The name and props of every component element created (not DOM elements), in order. */
export function components(): [string, Record<string, unknown>][] {
  return created
    .filter((c) => typeof c.type === "function")
    .map((c) => [(c.type as { name: string }).name, c.props]);
}

/**
 * What a component's hooks did while it rendered: every effect (the server renderer runs none:
 * the tests run them), every state update (after rendering the server renderer ignores them) and
 * initial states to start with instead of the component's own (keyed by the component's initial
 * value). With `vi.mock("react", async (orig) => spyReact(await orig()))` (imported as above).
 */
export const hooks = {
  effects: [] as (() => void | (() => void))[],
  updates: [] as unknown[],
  initial: new Map<unknown, unknown>(),
};

type ReactModule = typeof import("react");

/** React with useEffect and useState recording into `hooks`. */
export function spyReact(m: ReactModule): ReactModule {
  return {
    ...m,
    useEffect: (fn: () => void | (() => void), deps?: readonly unknown[]) => {
      hooks.effects.push(fn);
      m.useEffect(fn, deps);
    },
    useState: <S>(init: S | (() => S)) => {
      const [s, set] = m.useState(hooks.initial.has(init) ? (hooks.initial.get(init) as S) : init);
      return [
        s,
        (v: unknown) => {
          hooks.updates.push(v);
          set(v as S);
        },
      ];
    },
  } as ReactModule;
}

/** Empties `hooks` (after each test). */
export function clearHooks(): void {
  hooks.effects.length = 0;
  hooks.updates.length = 0;
  hooks.initial.clear();
}
