/** Finding blocks by name on the BlockTable (block-search.tsx), pure. */

/** Names that contain `query` (any case), in the order given; none for an empty query. */
export function matchingNames(names: readonly string[], query: string): string[] {
  const q = query.trim().toLowerCase();
  return q === "" ? [] : names.filter((n) => n.toLowerCase().includes(q));
}
