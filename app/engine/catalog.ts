import type { AnyBlockDefinition } from "./block";

/**
 * Every block type by its `Type` name — and by its aliases (MOSAIC's class names), which map to
 * the same definition (`def.type` is then the canonical name). Built once from an explicit list
 * (app/blocks/catalog.ts).
 */
export type Catalog = ReadonlyMap<string, AnyBlockDefinition>;

export function createCatalog(defs: readonly AnyBlockDefinition[]): Catalog {
  const m = new Map<string, AnyBlockDefinition>();
  for (const d of defs) {
    for (const name of [d.type, ...(d.aliases ?? [])]) {
      if (m.has(name)) throw new Error(`block type '${name}' is registered twice`);
      m.set(name, d);
    }
  }
  return m;
}

/** The distinct definitions of a catalog (without the aliases). */
export function catalogTypes(catalog: Catalog): AnyBlockDefinition[] {
  return [...catalog].filter(([name, d]) => name === d.type).map(([, d]) => d);
}
