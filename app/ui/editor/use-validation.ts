/**
 * The editor's problems are the engine's: each text (after a short pause in typing) goes to the
 * engine in a `validate` request, which runs the same check as `mosaic validate`
 * (app/engine/validate.ts), and its diagnostics are shown in the words the CLI prints, all at
 * once and positioned. While a newer text is being checked the last answer stays on screen.
 */
import { useEffect, useRef, useState } from "react";
import type { EngineClient } from "../client/engine-client";
import type { EditIssue } from "./model";
import { issuesFromReply } from "./validation-issues";

export { issueFromDiagnostic, issuesFromReply } from "./validation-issues";

/** Typing pauses this long before the text is checked. */
const PAUSE_MS = 250;

export interface Validation {
  /** The problems of the last text checked. */
  issues: EditIssue[];
  /** The text on screen is newer than the one `issues` are about. */
  checking: boolean;
}

interface Checked {
  file: string;
  text: string;
  issues: EditIssue[];
}

export function useValidation(client: EngineClient, file: string, text: string): Validation {
  const [checked, setChecked] = useState<Checked | undefined>();
  const first = useRef(true);
  useEffect(() => {
    let live = true;
    const check = (): void => {
      void client.request({ type: "validate", file, source: text }).then((r) => {
        if (live) setChecked({ file, text, issues: issuesFromReply(r) });
      });
    };
    const timer = setTimeout(check, first.current ? 0 : PAUSE_MS);
    first.current = false;
    return () => {
      live = false;
      clearTimeout(timer);
    };
  }, [client, file, text]);
  const checking = checked === undefined || checked.text !== text || checked.file !== file;
  return { issues: checked?.issues ?? [], checking };
}
