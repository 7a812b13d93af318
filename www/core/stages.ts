// Time per stage of the page's work (hand-off, transfer, drawing, …), for the per-stage
// profile of docs/performance.md. Off until a benchmark calls `reset()` on
// `globalThis.__dropsliceStages` (scripts/bench_table.mjs does, in the page and in each
// worker): a stage then costs one test of a flag.

export class StageClock {
  private on = false;
  private ms: Record<string, number> = {};
  /** What the extra counters counted of work set aside ([[aside]]), left out of `read()`. */
  private left: Record<string, number> = {};
  /** What else `read()` adds (the worker: the core's own counters). */
  constructor(private readonly extra: { reset(on: boolean): void; read(): Record<string, number> } | null = null) {}

  /** Counters on, from zero. */
  reset(): void {
    this.on = true;
    this.ms = {};
    this.left = {};
    this.extra?.reset(true);
  }

  /** Counters off. */
  stop(): void {
    this.on = false;
    this.extra?.reset(false);
  }

  read(): Record<string, number> {
    const extra = this.on ? (this.extra?.read() ?? {}) : {};
    for (const [k, v] of Object.entries(this.left)) if (k in extra) extra[k] -= v;
    return { ...extra, ...this.ms };
  }

  /** Runs `f` leaving what the extra counters count during it out of `read()`: work that is no
   *  part of the job (a worker's warm-up) does not count in its stages. */
  aside<T>(f: () => T): T {
    if (!this.on || !this.extra) return f();
    const before = this.extra.read();
    try {
      return f();
    } finally {
      for (const [k, v] of Object.entries(this.extra.read())) this.left[k] = (this.left[k] ?? 0) + v - (before[k] ?? 0);
    }
  }

  /** Runs `f`, adding its time to `name` while the counters are on. */
  time<T>(name: string, f: () => T): T {
    if (!this.on) return f();
    const t0 = performance.now();
    try {
      return f();
    } finally {
      this.ms[name] = (this.ms[name] ?? 0) + performance.now() - t0;
    }
  }

  /** Adds the time since `t0` (a `performance.now()`) to `name`. */
  since(name: string, t0: number): void {
    if (this.on) this.ms[name] = (this.ms[name] ?? 0) + performance.now() - t0;
  }

  /** Keeps the largest `ms` given for `name` (the longest of a kind of call). */
  max(name: string, ms: number): void {
    if (this.on) this.ms[name] = Math.max(this.ms[name] ?? 0, ms);
  }

  get active(): boolean {
    return this.on;
  }
}

/** Makes `clock` reachable by the benchmark as `globalThis.__dropsliceStages`. */
export function publish(clock: StageClock): StageClock {
  (globalThis as unknown as { __dropsliceStages: StageClock }).__dropsliceStages = clock;
  return clock;
}
