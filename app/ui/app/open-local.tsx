/**
 * Opening a pipeline from this computer (issue 17, defect 5). _Open file…_ reads one file; a
 * page is never told which folder it is in, so a block's relative path (a FilePlayer's File, a
 * model) cannot be read next to it: the engine says so in one error, and this offers to open the
 * folder. _Open folder…_ (the in-page engine only) hands the engine the folder's files (blob:
 * URLs, read when a block asks); with several pipelines in it, it asks which one to open.
 */
import { useEffect, useRef, useState } from "react";
import { MAX_FOLDER_FILES, OPEN_ITS_FOLDER, type LocalFolder } from "../../engine/protocol-folder";
import type { Reply } from "../client/engine-client";
import { useEngine } from "../client/hooks";
import "./open-local.css";

interface Folder {
  /** Path in the folder (its name first, '/'-separated) → the file. */
  files: Map<string, File>;
  urls: LocalFolder;
  /** The pipelines in it (.yaml, .yml), by path. */
  pipelines: string[];
  name: string;
  /** Files left out (hidden folders, node_modules, over MAX_FOLDER_FILES). */
  skipped: number;
}

const skip = (path: string): boolean =>
  path.split("/").some((p) => p.startsWith(".") || p === "node_modules");

/** The files of a picked folder, with a URL the in-page engine can read for each. */
function readFolder(list: FileList): Folder {
  const files = new Map<string, File>();
  const urls: Record<string, string> = {};
  let skipped = 0;
  for (const f of Array.from(list)) {
    const path = f.webkitRelativePath || f.name;
    if (skip(path) || files.size >= MAX_FOLDER_FILES) {
      skipped++;
      continue;
    }
    files.set(path, f);
    urls[path] = URL.createObjectURL(f);
  }
  const pipelines = [...files.keys()].filter((p) => /\.ya?ml$/i.test(p)).sort();
  const name = [...files.keys()][0]?.split("/")[0] ?? "";
  return { files, urls, pipelines, name, skipped };
}

function forget(folder: Folder | null): void {
  for (const url of Object.values(folder?.urls ?? {})) URL.revokeObjectURL(url);
}

/** The attribute that makes a file input pick a folder (not in React's types). */
const DIRECTORY = { webkitdirectory: "" } as Record<string, string>;

/** A file opened alone that names files next to it: its name and text. */
interface Need {
  name: string;
  text: string;
}

/** The file asked for (same name; the same text when several have it), else undefined. */
async function find(f: Folder, want: Need): Promise<string | undefined> {
  const same = f.pipelines.filter((p) => p.split("/").pop() === want.name);
  if (same.length <= 1) return same[0];
  for (const p of same) if ((await f.files.get(p)!.text()) === want.text) return p;
  return undefined;
}

interface OpenLocalProps {
  /** The engine runs in this page (it can read what the page hands it). */
  inPage: boolean;
  /** Loads (and starts) a pipeline's text. */
  onOpen(file: string, text: string): Promise<Reply>;
  notify(message: string, level?: "info" | "error"): void;
}

/** OpenLocal's state (the folder asked for, the folder to choose in) and its input handlers. */
function useOpenLocal({ inPage, onOpen, notify }: OpenLocalProps) {
  const client = useEngine();
  const folderInput = useRef<HTMLInputElement>(null);
  const folder = useRef<Folder | null>(null);
  /** A file opened alone that names files next to it: its folder is asked for. */
  const [need, setNeed] = useState<Need | null>(null);
  const [choose, setChoose] = useState<Folder | null>(null);
  useEffect(() => () => forget(folder.current), []);

  const openFile = async (e: React.ChangeEvent<HTMLInputElement>): Promise<void> => {
    const f = e.target.files?.[0];
    e.target.value = "";
    if (!f) return;
    const text = await f.text();
    setNeed(null);
    setChoose(null);
    if (inPage) client.openedLocally(f.name, {});
    const r = await onOpen(f.name, text);
    const wantsFolder = (r.diagnostics ?? []).some((d) => d.message.includes(OPEN_ITS_FOLDER));
    if (inPage && wantsFolder) setNeed({ name: f.name, text });
  };

  const openFromFolder = async (path: string, from: Folder): Promise<void> => {
    setChoose(null);
    setNeed(null);
    client.openedLocally(path, from.urls);
    await onOpen(path, await from.files.get(path)!.text());
  };

  const openFolder = async (e: React.ChangeEvent<HTMLInputElement>): Promise<void> => {
    const list = e.target.files;
    if (!list || list.length === 0) return;
    forget(folder.current);
    const f = readFolder(list);
    e.target.value = "";
    folder.current = f;
    if (f.skipped > 0)
      notify(`${f.name}: ${f.skipped} files left out (hidden, node_modules or too many)`);
    const wanted = need ? await find(f, need) : undefined;
    if (need && wanted === undefined) {
      notify(`${need.name} is not in the folder ${f.name}: pick the folder that holds it`, "error");
      return;
    }
    const only = wanted ?? (f.pipelines.length === 1 ? f.pipelines[0] : undefined);
    if (only !== undefined) await openFromFolder(only, f);
    else if (f.pipelines.length === 0)
      notify(`No pipeline (.yaml) in the folder ${f.name}`, "error");
    else setChoose(f);
  };

  return { folderInput, need, setNeed, choose, setChoose, openFile, openFromFolder, openFolder };
}

/** _Open file…_, _Open folder…_ (in-page engine) and what they ask: the folder, which pipeline. */
export function OpenLocal(props: OpenLocalProps) {
  const { folderInput, need, setNeed, choose, setChoose, openFile, openFromFolder, openFolder } =
    useOpenLocal(props);
  return (
    <span className="open-local">
      <OpenFileButton onChange={(e) => void openFile(e)} />
      {props.inPage ? (
        <OpenFolderButton inputRef={folderInput} onChange={(e) => void openFolder(e)} />
      ) : null}
      {need ? (
        <NeedFolder
          name={need.name}
          onOpen={() => folderInput.current?.click()}
          onClose={() => setNeed(null)}
        />
      ) : null}
      {choose ? (
        <ChoosePipeline
          folder={choose}
          onPick={(p) => void openFromFolder(p, choose)}
          onClose={() => setChoose(null)}
        />
      ) : null}
    </span>
  );
}

/** What a file input calls when files are picked. */
type OnInputChange = (e: React.ChangeEvent<HTMLInputElement>) => void;

/** _Open file…_: a button that picks one pipeline file. */
function OpenFileButton({ onChange }: { onChange: OnInputChange }) {
  return (
    <label className="button file-open" title="Load a pipeline file from this computer">
      Open file…
      <input type="file" accept=".yaml,.yml,text/yaml" className="sr-only" onChange={onChange} />
    </label>
  );
}

/** _Open folder…_: a button that picks a folder (its input is also clicked by NeedFolder). */
function OpenFolderButton({
  inputRef,
  onChange,
}: {
  inputRef: React.RefObject<HTMLInputElement | null>;
  onChange: OnInputChange;
}) {
  return (
    <label
      className="button folder-open"
      title="Open a folder of this computer: a pipeline in it and the data files it names"
    >
      Open folder…
      <input ref={inputRef} type="file" {...DIRECTORY} className="sr-only" onChange={onChange} />
    </label>
  );
}

function NeedFolder({ name, onOpen, onClose }: { name: string; onOpen(): void; onClose(): void }) {
  return (
    <div className="open-local__pop" role="alert" data-needs-folder={name}>
      <p>
        <strong>{name}</strong> names files next to it, and a browser never tells a page which
        folder a picked file is in. Open the folder that holds it and its data (a parent folder will
        do).
      </p>
      <div className="open-local__actions">
        <button type="button" className="primary" onClick={onOpen}>
          Open its folder…
        </button>
        <button type="button" onClick={onClose}>
          Not now
        </button>
      </div>
    </div>
  );
}

function ChoosePipeline({
  folder,
  onPick,
  onClose,
}: {
  folder: Folder;
  onPick(path: string): void;
  onClose(): void;
}) {
  return (
    <div className="open-local__pop" role="dialog" aria-label={`Pipelines in ${folder.name}`}>
      <p>
        <strong>{folder.name}</strong> holds {folder.pipelines.length} pipelines: which one?
      </p>
      <ul className="open-local__list">
        {folder.pipelines.map((p) => (
          <li key={p}>
            <button type="button" data-pipeline-file={p} onClick={() => onPick(p)}>
              {p.slice(folder.name.length + 1)}
            </button>
          </li>
        ))}
      </ul>
      <div className="open-local__actions">
        <button type="button" onClick={onClose}>
          Cancel
        </button>
      </div>
    </div>
  );
}
