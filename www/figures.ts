// The figures of a slice that the page still computes itself, all in this one module:
// droplets by role and travel (sums of the layers), the summary of the runs of layers (for the
// G-code's header and footer), the part's coverage and worst layer (from the layers' analyses),
// nothing-to-print, and the estimates (volume, mass, print time). DESIGN.md wants the core to
// compute them; switching to the core's figures is a change of this module (and of what
// store.ts hands it), not of the views.

import { addNumbers, type Counts, type LayerAnalysis, type LayerData, type SliceUnit } from "./protocol";

export class Figures {
  totals: Counts = { outer: 0, inner: 0, fill: 0 };
  travelTotal = 0;
  /** Sum of the layers' summaries (the core's Summary, for the header and footer). */
  summary: Record<string, unknown> = {};
  regionArea = 0;
  coveredArea = 0;
  /** The worst layer: the one with the largest connected void. */
  worst: { index: number; area: number } | null = null;

  /** A layer's droplets and travel (once per layer). */
  addLayer(l: LayerData): void {
    this.totals.outer += l.counts.outer;
    this.totals.inner += l.counts.inner;
    this.totals.fill += l.counts.fill;
    this.travelTotal += l.travelMm;
  }

  /** A layer's void analysis (once per layer). */
  addAnalysis(index: number, a: LayerAnalysis): void {
    this.regionArea += a.region_area;
    this.coveredArea += a.covered_area;
    const v = a.largest_void;
    if (v && (!this.worst || v.area > this.worst.area)) this.worst = { index, area: v.area };
  }

  /** A run of layers is complete: its part of the summary. */
  addUnit(u: SliceUnit): void {
    if (u.summary) addNumbers(this.summary, u.summary);
  }

  /** The summary as the core's header, footer and repairs take it. */
  summaryJson(layers: number): string {
    return JSON.stringify({ ...this.summary, layers });
  }

  get droplets(): number {
    return this.totals.outer + this.totals.inner + this.totals.fill;
  }

  /** Like the CLI: no droplet at all, no code. */
  get nothingToPrint(): boolean {
    return this.droplets === 0;
  }

  /** Covered share of the part's region over the layers analysed so far (null before any). */
  partCoverage(analysed: number): number | null {
    return analysed > 0 && this.regionArea > 0 ? this.coveredArea / this.regionArea : null;
  }

  /** Material volume (mm³), mass (g) and print time (s) from the droplet size and the settings'
   *  material_density, droplet_rate and travel_speed (`setting(name, default)`). */
  estimates(dropletWidth: number, layerHeight: number, setting: (name: string, fallback: number) => number): { volume: number; mass: number; seconds: number } {
    const volume = this.droplets * dropletWidth * dropletWidth * layerHeight; // mm³
    const mass = (volume / 1000) * setting("material_density", 1.04);
    const seconds = this.droplets / setting("droplet_rate", 100) + this.travelTotal / setting("travel_speed", 50);
    return { volume, mass, seconds };
  }
}
