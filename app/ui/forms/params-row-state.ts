/**
 * A param row's state (see ParamRow): the engine's value, the value being edited and the
 * engine's reply to the last change sent.
 */
import { useEffect, useMemo, useRef, useState, type RefObject } from "react";
import type { SetResult } from "./params-form";
import { deepEqual, hasInvalid, validate, type Field, type Issue, type JsonSchema } from "./schema";

export type Reply =
  | { kind: "idle" }
  | { kind: "pending" }
  | { kind: "ok"; message: string }
  | { kind: "error"; message: string };

type SetState<T> = (next: T | ((prev: T) => T)) => void;

/** A ref that is true while the component is mounted. */
function useMounted(): RefObject<boolean> {
  const mounted = useRef(true);
  useEffect(() => {
    mounted.current = true;
    return () => {
      mounted.current = false;
    };
  }, []);
  return mounted;
}

/** The engine's value changed (another client, a reload): shown at once, unless being edited. */
function useFollowEngine(
  initial: unknown,
  setCurrent: SetState<unknown>,
  setDraft: SetState<unknown>,
  setReply: SetState<Reply>,
): void {
  const shownInitial = useRef(initial);
  useEffect(() => {
    const before = shownInitial.current;
    shownInitial.current = initial;
    if (deepEqual(before, initial)) return;
    setCurrent(initial);
    setDraft((d: unknown) => (deepEqual(d, before) ? initial : d));
    setReply((r) => (r.kind === "pending" ? r : { kind: "idle" }));
  }, [initial, setCurrent, setDraft, setReply]);
}

/** What is wrong with `value` for `field` (a missing required value first). */
function fieldIssues(field: Field, value: unknown, root: JsonSchema): Issue[] {
  const is: Issue[] = validate(field.schema, value, root);
  if (value === undefined && field.required) is.unshift({ path: [], message: "required" });
  return is;
}

export interface ParamDraft {
  /** The engine's value (the last one it accepted or sent). */
  current: unknown;
  draft: unknown;
  setDraft: (v: unknown) => void;
  reply: Reply;
  setReply: (r: Reply) => void;
  issues: Issue[];
  /** Sends `value` when it is valid, editable and neither the current nor the pending one. */
  commit: (value: unknown) => Promise<void>;
  /** Drops the draft: back to the current value. */
  revert: () => void;
}

export function useParamDraft(
  field: Field,
  root: JsonSchema,
  initial: unknown,
  editable: boolean,
  send: ((param: string, value: unknown) => Promise<SetResult>) | undefined,
): ParamDraft {
  const [current, setCurrent] = useState<unknown>(initial);
  const [draft, setDraft] = useState<unknown>(initial);
  const [reply, setReply] = useState<Reply>({ kind: "idle" });
  const mounted = useMounted();
  const inFlight = useRef<unknown>(undefined);
  useFollowEngine(initial, setCurrent, setDraft, setReply);
  const issues = useMemo(() => fieldIssues(field, draft, root), [field, draft, root]);

  const commit = async (value: unknown): Promise<void> => {
    if (!editable || !send) return;
    if (fieldIssues(field, value, root).length || hasInvalid(value)) return;
    if (
      deepEqual(value, current) ||
      (inFlight.current !== undefined && deepEqual(value, inFlight.current))
    )
      return;
    inFlight.current = value;
    setReply({ kind: "pending" });
    const r = await send(field.name, value);
    inFlight.current = undefined;
    if (!mounted.current) return;
    if (r.ok) {
      setCurrent(value);
      setReply({ kind: "ok", message: r.message ?? "applied" });
    } else {
      setReply({ kind: "error", message: r.message ?? "rejected by the engine" });
    }
  };
  const revert = (): void => {
    setDraft(current);
    setReply({ kind: "idle" });
  };
  return { current, draft, setDraft, reply, setReply, issues, commit, revert };
}
