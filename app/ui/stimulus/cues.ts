/** What the UI knows of a Stimulus block's protocol without React: its phases and cue labels. */

export const PHASES = ["rest", "rise", "hold", "capture", "fall", "end"] as const;
export type Phase = (typeof PHASES)[number];
/** Label names in cue-index order, as the Stimulus block numbers them (Labels, then Tasks). */
export function cueLabels(params: Record<string, unknown>): string[] {
  const names: string[] = [];
  const labels = params.Labels;
  if (labels !== null && typeof labels === "object" && !Array.isArray(labels)) {
    names.push(...Object.keys(labels));
  }
  const tasks = params.Tasks;
  if (Array.isArray(tasks)) {
    for (const t of tasks) {
      const label =
        typeof t === "string"
          ? t
          : t !== null && typeof t === "object"
            ? (t as { Label?: unknown }).Label
            : undefined;
      if (typeof label === "string" && !names.includes(label)) names.push(label);
    }
  }
  return names;
}
