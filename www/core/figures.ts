// The figures of a slice, as the core computed them (src/output/summary.rs): droplets by role,
// travel, material volume and mass, print time, part coverage, void area, the worst layer,
// what slicing repaired, and nothing-to-print. The page keeps the core's per-unit summaries
// (it never adds them up) and asks a worker to merge them into figures; the views only show
// what comes back. A .gco file opened for viewing has no core figures: its droplets are
// counted as its layers are read.

import type { Pool } from "./client";
import type { Counts, ErrorValue, Figures as CoreFigures, LayerData, SliceFigures, SliceUnit, Summary } from "./protocol";

/** One discharge unit's figures: its droplets (its parts' and, for the unit that prints it,
 *  the support), and, for a slice, their material (mm³), mass (g, with the unit's
 *  `…material_density`), droplet time (s, with its `…droplet_rate`) and the predicted density
 *  of its parts (%, the 3D estimate; null without it or without parts of the unit). */
export interface UnitFigures {
  droplets: number;
  volume: number | null;
  mass: number | null;
  seconds: number | null;
  density: number | null;
}

const finiteOr = (v: unknown, or: number | null): number | null => (typeof v === "number" && Number.isFinite(v) ? v : or);

/** Unit u's figures of the core's `c` (one entry per unit; a unit beyond them prints
 *  nothing). */
function coreUnit(c: CoreFigures, u: number): UnitFigures {
  const x = c.units?.[u];
  return {
    droplets: finiteOr(x?.droplets, 0)!,
    volume: finiteOr(x?.volume_mm3, 0),
    mass: finiteOr(x?.mass_g, 0),
    seconds: finiteOr(x?.seconds, 0),
    density: finiteOr(x?.predicted_density, null),
  };
}

export class Figures {
  /** The core's summaries of the slice's units, and of a later analysis pass. */
  private parts: Summary[] = [];
  private analysisParts: Summary[] = [];
  /** The last figures from the core (null before the first answer). */
  core: CoreFigures | null = null;
  /** The merged summary, for the G-code's header and footer. */
  summary: Summary | null = null;
  /** Set by the core when every layer is in and not one droplet fits. */
  nothingToPrint: ErrorValue | null = null;
  /** A .gco file's droplets and travel, as read. */
  private read: Counts & { units: number[] } = { outer: 0, inner: 0, fill: 0, support: 0, units: [0, 0, 0, 0] };
  private readTravel = 0;
  /** A .gco file's droplets per unit (after `T0`, `T1`, …), as read. */
  private readUnits: number[] = [0];
  private running: Promise<void> | null = null;
  private again = false;

  /** Why a .gco file has no estimates (its header does not give the settings). */
  readNote: string | null = null;
  /** Why a .gco file's figures are computed from its commands (null: they are its header's,
   *  the figures of the slice that wrote it, or there are none). */
  movesNote: string | null = null;

  /** A .gco file read to its end: the core's figures (its header's own, else computed from
   *  its commands with its header's settings: `moves` says why), or why there are none. */
  setRead(figures: CoreFigures | null, note: string | null, moves: string | null): void {
    this.core = figures;
    this.readNote = figures ? null : note;
    this.movesNote = figures ? moves : null;
  }

  /** A .gco file whose figures are its header's (the slice's, with its roles). */
  get fromHeader(): boolean {
    return this.core !== null && this.readNote === null && this.movesNote === null;
  }

  /** A layer of a .gco file (once per layer). */
  addReadLayer(l: LayerData): void {
    this.read.outer += l.counts.outer;
    this.read.inner += l.counts.inner;
    this.read.fill += l.counts.fill;
    l.counts.units?.forEach((d, u) => (this.read.units[u] = (this.read.units[u] ?? 0) + d));
    l.counts.parts.forEach((d, u) => (this.readUnits[u] = (this.readUnits[u] ?? 0) + d));
    this.readTravel += l.travelMm;
  }

  /** A run of layers is complete: its summary (of a slice, or only analyses). */
  addUnit(u: SliceUnit): void {
    if (u.gcode) this.parts.push(u.summary);
    else this.analysisParts.push(u.summary);
  }

  /** A new analysis pass starts: the analyses of an unfinished earlier one are dropped. */
  restartAnalysis(): void {
    this.analysisParts = [];
  }

  /** Asks a worker for the figures of every summary so far, one request at a time; resolves
   *  once the figures include every summary added before the call. `changed` runs after
   *  each answer. */
  refresh(pool: Pool, changed: () => void): Promise<void> {
    if (this.running) {
      this.again = true;
      return this.running;
    }
    const run = async () => {
      try {
        do {
          this.again = false;
          this.apply(await pool.figures([...this.parts, ...this.analysisParts]));
          changed();
        } while (this.again);
      } finally {
        this.running = null;
      }
    };
    this.running = run();
    return this.running;
  }

  private apply(f: SliceFigures): void {
    this.core = f.figures;
    this.summary = f.summary;
    this.nothingToPrint = f.nothing_to_print;
  }

  get totals(): Counts {
    return this.core?.counts ?? this.read;
  }

  get travelTotal(): number {
    return this.core?.travel_mm ?? this.readTravel;
  }

  get droplets(): number {
    if (this.core) return this.core.droplets;
    const t = this.totals;
    return t.outer + t.inner + t.fill + (t.support ?? 0);
  }

  /** Each of `n` units' figures (index u: unit u's); a .gco file's droplets after each `T`,
   *  without estimates. */
  units(n: number): UnitFigures[] {
    const c = this.core;
    return Array.from({ length: n }, (_, u) =>
      c ? coreUnit(c, u) : { droplets: this.readUnits[u] ?? 0, volume: null, mass: null, seconds: null, density: null },
    );
  }

  /** Overhang area of the part, mm² (summed over the layers; null for a .gco file). */
  get unsupportedArea(): number | null {
    return this.core?.unsupported_area ?? null;
  }

  /** The layer with the largest overhang area. */
  get worstOverhang(): { index: number; area: number } | null {
    return this.core?.worst_overhang ?? null;
  }

  /** Layers analysed (the core's count). */
  get analysed(): number {
    return this.core?.analysed_layers ?? 0;
  }

  /** Covered share of the part's region over the layers analysed so far (null before any). */
  get partCoverage(): number | null {
    return this.core?.coverage ?? null;
  }

  /** The worst layer: the one with the largest connected void. */
  get worst(): { index: number; area: number } | null {
    return this.core?.worst_layer ?? null;
  }

  /** What slicing repaired. */
  get repairs(): string[] {
    return this.core?.repairs ?? [];
  }

  /** Material volume (mm³), mass (g) and print time (s); null for a .gco file. */
  get estimates(): { volume: number; mass: number; seconds: number } | null {
    const c = this.core;
    if (!c) return null;
    const u0 = coreUnit(c, 0);
    return { volume: u0.volume ?? 0, mass: u0.mass ?? 0, seconds: c.print_seconds };
  }
}
