// The "Voids" block of the statistics: this layer, the part, the worst layer (and its button).

import type { Slice } from "../core/store";
import { $, nf, setText } from "./dom";

const pct = (x: number) => `${(x * 100).toFixed(1)} %`;
const mm2 = (x: number) => `${x < 0.1 ? x.toFixed(3) : x.toFixed(2)} mm²`;

const finite = (x: number | null | undefined): number | null => (x !== null && x !== undefined && Number.isFinite(x) ? x : null);

/** `n`: the units shown (the rows of units 1 … n − 1 are made by stats.ts). */
export function writeVoids(s: Slice | null, current: number, n: number): void {
  const a = s?.analysis[current];
  setText("stat-coverage", a ? pct(a.coverage) : "–");
  setText("stat-void", a ? mm2(a.void_area) : "–");
  const v = a?.largest_void;
  setText("stat-largest", v ? `${mm2(v.area)}${v.at_boundary ? " (edge)" : ""}` : a ? "none" : "–");
  const partial = s && s.analysed < s.layers ? " so far" : "";
  const coverage = s?.figures.partCoverage ?? null;
  setText("stat-part-coverage", coverage !== null ? pct(coverage) + partial : "–");
  // the core's 3D void estimate only (the page never makes up a density of its own), per unit
  // that prints parts
  const dens = (d: number | null) => (d !== null ? `${d.toFixed(1)} %${partial}` : "–");
  const byUnit = s?.figures.core ? s.figures.units(n).map((u) => finite(u.density)) : new Array<null>(n).fill(null);
  const d0 = byUnit[0] ?? null;
  setText("stat-density", dens(d0));
  for (let u = 1; u < n; u++) {
    setText(`stat-density${u}`, dens(byUnit[u]));
    $(`stat-density${u}`).hidden = $(`stat-density${u}-label`).hidden = byUnit[u] === null;
  }
  $("stat-density").title =
    d0 !== null
      ? "100 % minus the 3D void fraction of the analysed layers (each slab with the droplet spheroids of the layers below and above), of unit 0's parts: a geometric estimate from the droplet model, not a measured density"
      : byUnit.some((d) => d !== null)
        ? "The job has no parts of unit 0"
        : "Turn on Voids: the 3D void analysis estimates it";
  const worst = s?.figures.worst;
  setText("stat-worst", worst ? `${nf.format(worst.index + 1)} · ${mm2(worst.area)}` : "–");
  ($("btn-worst") as HTMLButtonElement).disabled = !worst;
  const hint = $("voids-hint");
  if (s?.source === "gco") hint.textContent = "Voids are analysed for sliced STL files.";
  else if (!s || s.analysed === 0) hint.replaceChildren("Turn on ", Object.assign(document.createElement("b"), { textContent: "Voids" }), " to analyse.");
  else if (s.analysed < s.layers) hint.textContent = `Analysed ${nf.format(s.analysed)} of ${nf.format(s.layers)} layers.`;
  else hint.textContent = "Worst: largest connected void.";
}
