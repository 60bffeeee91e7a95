/**
 * The participant window's address: the clinician's page URL (its `token` for `mosaic serve`
 * kept) with `view=participant`, the Stimulus block's name and, in the browser build, the
 * `relay` channel on which the clinician's page lends its engine (app/web/participant-relay.ts).
 */
export const PARTICIPANT_VIEW = "participant";

/** The participant window's URL for the Stimulus block `block`, from the clinician's `href`. */
export function participantUrl(href: string, block: string, relay?: string): string {
  const url = new URL(href);
  url.hash = "";
  url.searchParams.delete("pipeline");
  url.searchParams.set("view", PARTICIPANT_VIEW);
  url.searchParams.set("block", block);
  if (relay !== undefined) url.searchParams.set("relay", relay);
  else url.searchParams.delete("relay");
  return url.toString();
}

export interface ParticipantParams {
  /** The Stimulus block to show (undefined: the pipeline's first). */
  block: string | undefined;
  /** The clinician page's relay channel (browser build). */
  relay: string | undefined;
}

/** The participant view's params of a page's query string; undefined for the clinician's page. */
export function participantParams(search: string): ParticipantParams | undefined {
  const q = new URLSearchParams(search);
  if (q.get("view") !== PARTICIPANT_VIEW) return undefined;
  return { block: q.get("block") || undefined, relay: q.get("relay") || undefined };
}
