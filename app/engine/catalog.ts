import type { AnyBlockDefinition } from "./block";

/** Every block type by its `Type` name. Built once from an explicit list (app/blocks/catalog.ts). */
export type Catalog = ReadonlyMap<string, AnyBlockDefinition>;

export function createCatalog(defs: readonly AnyBlockDefinition[]): Catalog {
  const m = new Map<string, AnyBlockDefinition>();
  for (const d of defs) {
    if (m.has(d.type)) throw new Error(`block type '${d.type}' is registered twice`);
    m.set(d.type, d);
  }
  return m;
}
