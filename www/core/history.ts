// Undo and redo: a bounded history of states (the page keeps snapshots of its build job and
// settings, flows/history.ts). Each entry names the change that left it ("remove part"), so
// the buttons can say what they undo. No DOM.

import type { Job, JobModel, Part } from "./job";
import type { Settings } from "./settings";

/** A state left behind and the change that left it. */
export interface Entry<S> {
  state: S;
  label: string;
}

/** States the history keeps by default (older ones are forgotten). */
export const HISTORY_DEPTH = 100;

export class History<S> {
  private past: Entry<S>[] = [];
  private future: Entry<S>[] = [];
  /** The state now (null before the first). */
  present: S | null = null;

  /** `same` tells two states apart (equal states make no entry). */
  constructor(
    private readonly same: (a: S, b: S) => boolean,
    readonly depth = HISTORY_DEPTH,
  ) {
    if (!(Number.isInteger(depth) && depth > 0)) throw new RangeError("a history keeps at least one state");
  }

  /** `next` is the state after the change `label`: the state before becomes undoable and
   *  whatever was undone is no longer redoable. Returns whether an entry was made. */
  commit(next: S, label: string): boolean {
    const before = this.present;
    this.present = next;
    if (before === null || this.same(before, next)) return false;
    this.past.push({ state: before, label });
    if (this.past.length > this.depth) this.past.splice(0, this.past.length - this.depth);
    this.future = [];
    return true;
  }

  /** The state now, changed again by the same change (typing on in one field): no new entry. */
  amend(next: S): void {
    this.present = next;
  }

  /** Back one change: the state to restore and what was undone (null: nothing to undo). */
  undo(): Entry<S> | null {
    return this.step(this.past, this.future);
  }

  /** Forward one change (null: nothing to redo). */
  redo(): Entry<S> | null {
    return this.step(this.future, this.past);
  }

  private step(from: Entry<S>[], to: Entry<S>[]): Entry<S> | null {
    const e = from.pop();
    if (!e || this.present === null) return null;
    to.push({ state: this.present, label: e.label });
    this.present = e.state;
    return e;
  }

  /** Every state kept: those to undo to, the present, those to redo. */
  snapshots(): S[] {
    return [...this.past.map((e) => e.state), ...(this.present === null ? [] : [this.present]), ...this.future.map((e) => e.state)];
  }

  /** What Undo would undo (null: nothing). */
  get undoLabel(): string | null {
    return this.past.at(-1)?.label ?? null;
  }

  get redoLabel(): string | null {
    return this.future.at(-1)?.label ?? null;
  }
}

/** The page's state as the history keeps it: the job (the object, so that undoing a new job
 *  brings the previous one back whole), its files and parts as they were, the selection and
 *  the settings. Parts are never changed in place (an edit makes new ones), so keeping them is
 *  enough. A snapshot holds no display mesh: those are the job's, one per file and item
 *  (`Job.meshes`), shared by every state of the job, so a hundred edits keep no hundred meshes. */
export interface Snapshot {
  job: Job | null;
  models: JobModel[];
  parts: Part[];
  selected: number | null;
  settings: Settings;
  /** Parts (ids and specs) and settings as text: equal keys are the same state. */
  key: string;
}

export function snapshotOf(job: Job | null, settings: Settings): Snapshot {
  const parts = job ? [...job.parts] : [];
  const key = JSON.stringify({ parts: parts.map((p) => [p.id, p.spec]), settings });
  return { job, models: job ? [...job.models.values()] : [], parts, selected: job?.selected ?? null, settings: { ...settings }, key };
}

export const sameSnapshot = (a: Snapshot, b: Snapshot): boolean => a.job === b.job && a.key === b.key;
