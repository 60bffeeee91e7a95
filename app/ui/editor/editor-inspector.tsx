/** The editor's inspector: the selected block's, or a hint when none is selected. */
import type { ReactNode } from "react";
import type { BlockTypeInfo, GraphInfo } from "../../engine/protocol";
import { Inspector } from "./inspector";
import type { EditBlock, EditIssue } from "./model";
import type { EditorModel } from "./use-editor";
import type { EditorEdits } from "./use-editor-edits";

export interface EditorInspectorProps {
  sel: EditBlock | undefined;
  ed: EditorModel;
  edits: EditorEdits;
  types: Map<string, BlockTypeInfo>;
  issues: readonly EditIssue[];
  graph: GraphInfo | undefined;
}

export function EditorInspector({
  sel,
  ed,
  edits,
  types,
  issues,
  graph,
}: EditorInspectorProps): ReactNode {
  if (!sel) return <p className="inspector__none">Select a block to edit it.</p>;
  return (
    <Inspector
      block={sel}
      type={types.get(sel.type)}
      issues={issues}
      runningBlock={graph?.blocks.find((b) => b.name === sel.name)}
      onRename={edits.rename}
      onDesiredRate={(r) => ed.edit((d) => d.setDesiredRate(sel.name, r))}
      onPath={(p) => ed.edit((d) => d.setPath(sel.name, p))}
      onInputs={(ins) => ed.edit((d) => d.setInputs(sel.name, ins))}
      onParam={edits.setParam}
    />
  );
}
