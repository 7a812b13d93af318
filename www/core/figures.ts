// The figures of a slice, as the core computed them (src/output/summary.rs): droplets by role,
// travel, material volume and mass, print time, part coverage, void area, the worst layer,
// what slicing repaired, and nothing-to-print. The page keeps the core's per-unit summaries
// (it never adds them up) and asks a worker to merge them into figures; the views only show
// what comes back. A .gco file opened for viewing has no core figures: its droplets are
// counted as its layers are read.

import type { Pool } from "./client";
import type { Counts, ErrorValue, Figures as CoreFigures, LayerData, SliceFigures, SliceUnit, Summary } from "./protocol";

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
  private read: Counts = { outer: 0, inner: 0, fill: 0, support: 0, unit1: 0 };
  private readTravel = 0;
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
    this.read.unit1 = (this.read.unit1 ?? 0) + (l.counts.unit1 ?? 0);
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

  /** Unit 1's droplets (support and unit-1 parts; a .gco file's after `T1`), and, for a
   *  slice, their material (mm³), mass (g, unit1_material_density) and each unit's droplet
   *  time (s). */
  get unit1(): { droplets: number; volume: number | null; mass: number | null; seconds0: number | null; seconds1: number | null } {
    const c = this.core;
    if (!c) return { droplets: this.read.unit1 ?? 0, volume: null, mass: null, seconds0: null, seconds1: null };
    return { droplets: c.unit1_droplets ?? 0, volume: c.unit1_volume_mm3 ?? 0, mass: c.unit1_mass_g ?? 0, seconds0: c.unit0_seconds ?? null, seconds1: c.unit1_seconds ?? null };
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
    return c ? { volume: c.volume_mm3, mass: c.mass_g, seconds: c.print_seconds } : null;
  }
}
