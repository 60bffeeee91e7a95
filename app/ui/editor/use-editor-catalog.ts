/**
 * The block catalog the editor offers (palette, inspector, YAML completion). It holds the loaded
 * pipeline's own blocks too (`Pipeline: { Blocks }`): asked again when another pipeline, or a new
 * version of its blocks, is loaded.
 */
import { useEffect, useMemo, useState } from "react";
import type { BlockTypeInfo, CatalogInfo, GraphInfo } from "../../engine/protocol";
import type { EngineClient } from "../client/engine-client";
import { typeIndex } from "./model";
import type { Notify } from "./use-editor-edits";

export interface EditorCatalog {
  catalog: CatalogInfo | undefined;
  /** The catalog by type name, aliases included. */
  types: Map<string, BlockTypeInfo>;
}

export function useEditorCatalog(
  client: EngineClient,
  graph: GraphInfo | undefined,
  onNotify: Notify,
): EditorCatalog {
  const [catalog, setCatalog] = useState<CatalogInfo | undefined>();
  const loadedTypes = graph ? `${graph.file}:${graph.blocks.map((b) => b.type).join(",")}` : "";
  useEffect(() => {
    let live = true;
    void client.catalog().then((c) => {
      if (live) setCatalog(c);
      if (!c) onNotify("The engine did not send its block catalog", "error");
    });
    return () => {
      live = false;
    };
  }, [client, onNotify, loadedTypes]);
  const types = useMemo(() => typeIndex(catalog), [catalog]);
  return { catalog, types };
}
