// The slice's layers as units of work shared by the page's workers (the pool, client.ts):
// the counter that hands them out in order, and a worker slicing from the job worker's draft
// whose output is held until the draft is confirmed (docs/page.md, *The preparation off the
// critical path*).

/** A run of consecutive layers [from, to). */
export interface Unit {
  from: number;
  to: number;
}

/** Hands out the units of layers [0, layers) in order, shared by all workers. A unit is small
 *  enough to share the work evenly and to show progress, and large enough that its round trip
 *  and its Blob cost little (a Blob costs about 0.5 ms, whatever its size). Units given back
 *  (a draft's that did not stand, see [[Speculation]]) are handed out again first. */
export class UnitCounter {
  private readonly size: number;
  private at = 0;
  private again: Unit[] = [];

  constructor(
    readonly layers: number,
    workers: number,
  ) {
    this.size = Math.max(1, Math.min(16, Math.ceil(layers / (4 * workers))));
  }

  next(): Unit | null {
    const back = this.again.shift();
    if (back) return back;
    if (this.at >= this.layers) return null;
    const from = this.at;
    this.at = Math.min(this.layers, from + this.size);
    return { from, to: this.at };
  }

  giveBack(units: Unit[]): void {
    this.again.push(...units);
    this.again.sort((a, b) => a.from - b.from);
  }
}

export function unitCounter(layers: number, workers: number): () => Unit | null {
  const c = new UnitCounter(layers, workers);
  return () => c.next();
}

/** A worker slicing from the job worker's draft before the job is made (`adopt_draft`): what
 *  it sends is held until the job worker confirms the job is the draft's (`confirm_job`), then
 *  passed on in order; if the job is refused or not the draft's, it is dropped and the units
 *  it took are given back. */
export class Speculation<H> {
  state: "draft" | "confirmed" | "dropped" = "draft";
  /** What the worker sent while a draft, to pass on once confirmed. */
  private held: (() => void)[] = [];
  /** The units it took while a draft. */
  readonly taken: Unit[] = [];
  /** Its units' lanes: they end when the counter has no unit left (or it was dropped). */
  lanes: Promise<void> = Promise.resolve();

  constructor(readonly h: H) {}

  pass(f: () => void): void {
    if (this.state === "confirmed") f();
    else if (this.state === "draft") this.held.push(f);
  }

  confirm(): void {
    this.state = "confirmed";
    const held = this.held;
    this.held = [];
    for (const f of held) f();
  }

  drop(counter: UnitCounter | null): void {
    if (this.state === "dropped") return;
    this.state = "dropped";
    this.held = [];
    this.lanes.catch(() => {}); // terminated: its calls reject
    counter?.giveBack(this.taken);
  }
}
