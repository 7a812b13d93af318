// Time per stage of the page's work (hand-off, transfer, drawing, …), for the per-stage
// profile of docs/performance.md. Off until a benchmark calls `reset()` on
// `globalThis.__dropsliceStages` (scripts/bench_table.mjs does, in the page and in each
// worker): a stage then costs one test of a flag.

export class StageClock {
  private on = false;
  private ms: Record<string, number> = {};
  /** What else `read()` adds (the worker: the core's own counters). */
  constructor(private readonly extra: { reset(on: boolean): void; read(): Record<string, number> } | null = null) {}

  /** Counters on, from zero. */
  reset(): void {
    this.on = true;
    this.ms = {};
    this.extra?.reset(true);
  }

  /** Counters off. */
  stop(): void {
    this.on = false;
    this.extra?.reset(false);
  }

  read(): Record<string, number> {
    return { ...(this.on ? (this.extra?.read() ?? {}) : {}), ...this.ms };
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
