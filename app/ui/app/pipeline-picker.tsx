/** The toolbar's pipeline picker: the example files, grouped by folder, with their titles. */
import type { PipelineEntry } from "./use-pipeline";

/** "demo.yaml", "bench/delsys.yaml": the file under pipelines/. */
export const shortName = (file: string): string => file.replace(/^pipelines\//, "");

export function PipelinePicker({
  index,
  selected,
  onSelect,
}: {
  index: readonly PipelineEntry[];
  selected: string;
  onSelect(file: string): void;
}) {
  const entries = index.some((e) => e.file === selected)
    ? index
    : [{ file: selected, title: selected }, ...index];
  const groups = new Map<string, PipelineEntry[]>();
  for (const e of entries) {
    const dir = shortName(e.file).includes("/") ? shortName(e.file).split("/")[0]! : "";
    groups.set(dir, [...(groups.get(dir) ?? []), e]);
  }
  const title = entries.find((e) => e.file === selected)?.title ?? "";
  return (
    <label className="picker" title={title}>
      <span className="picker__label">Pipeline</span>
      <select
        value={selected}
        onChange={(e) => onSelect(e.target.value)}
        aria-describedby="picker-title"
      >
        {[...groups].map(([dir, es]) =>
          dir === "" ? (
            es.map((e) => (
              <option key={e.file} value={e.file}>
                {shortName(e.file)}
              </option>
            ))
          ) : (
            <optgroup key={dir} label={dir}>
              {es.map((e) => (
                <option key={e.file} value={e.file}>
                  {shortName(e.file)}
                </option>
              ))}
            </optgroup>
          ),
        )}
      </select>
      <span id="picker-title" className="picker__title">
        {title}
      </span>
    </label>
  );
}
