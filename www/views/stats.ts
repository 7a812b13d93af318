// The statistics panel: the model, droplets by role, the estimates, this layer, the mesh
// warnings and the unit fix. The figures are the core's (figures.ts); nothing is computed here.

import type { Page } from "./page";
import type { Slice } from "../core/store";
import { writeCalibration } from "./calibrate";
import { $, duration, nf, setText } from "./dom";
import { requestPlot } from "./plot";
import { writeVoids } from "./voids";

const fmtMm = (x: number) => `${x.toFixed(1)}`;

/** The roles' names: a slice's, and those of a .gco file whose header gives its droplets by
 *  role (the slice's figures); a .gco file without them is counted by command (G26 droplets
 *  as loops, G25 lines as fill). The canvas draws a file's G26 droplets in the outer loop's
 *  colour, inner loops included. */
function roleLabels(source: "stl" | "gco", fromHeader: boolean): void {
  const gco = source === "gco";
  const byCommand = gco && !fromHeader;
  $("legend-0").textContent = gco ? (fromHeader ? "Loops (outer and inner)" : "Loop droplets (G26)") : "Outer loop";
  $("stat-label-0").textContent = byCommand ? "Loop droplets (G26)" : "Outer loop";
  $("legend-2").textContent = $("stat-label-2").textContent = byCommand ? "Fill lines (G25)" : "Fill";
  $("legend-1-wrap").hidden = gco;
  $("legend-unit1-label").textContent = gco ? "Unit 1 (after T1)" : "Unit-1 part";
  $("stat-unit1-label").textContent = byCommand ? "Unit 1 (after T1)" : "Unit 1, all";
  $("stat-support-label").hidden = $("stat-support").hidden = byCommand;
}

const mm2 = (x: number) => `${x < 0.1 ? x.toFixed(3) : x.toFixed(2)} mm²`;

/** Support and unit-1 droplets: the legend's entries, the droplet rows, unit 1's material,
 *  mass and time, and the overhang block. All figures are the core's. */
function writeUnit1(s: Slice | null, current: number): void {
  const f = s?.figures;
  const u = f?.unit1;
  const support = f?.totals.support ?? 0;
  const layer = s?.cache.get(current);
  let layerSupport = 0;
  let layerUnit1Part = 0;
  if (layer?.units) {
    for (let i = 0; i < layer.roles.length; i++) {
      if (layer.roles[i] === 3) layerSupport++;
      else if (layer.units[i] === 1) layerUnit1Part++;
    }
  }
  const unit1Parts = (u?.droplets ?? 0) - support;
  $("legend-support").hidden = !(support > 0 || layerSupport > 0);
  $("legend-unit1").hidden = !(unit1Parts > 0 || layerUnit1Part > 0);
  setText("stat-support", s ? nf.format(support) : "–");
  setText("stat-unit1", s ? nf.format(u?.droplets ?? 0) : "–");
  const any = (u?.droplets ?? 0) > 0 && u?.volume !== null;
  $("unit1-stats").hidden = !any;
  if (any && u) {
    setText("stat-volume1", u.volume !== null ? `${(u.volume / 1000).toFixed(2)} cm³` : "–");
    setText("stat-mass1", u.mass !== null ? `${u.mass.toFixed(2)} g` : "–");
    setText("stat-unit-times", u.seconds0 !== null && u.seconds1 !== null ? `${duration(u.seconds0)} · ${duration(u.seconds1)}` : "–");
  }
  // overhangs (the core's areas: per layer as the layers come in, the part's and the worst)
  const stl = s?.source === "stl";
  const a = stl ? s!.unsupportedArea[current] : undefined;
  setText("stat-overhang-layer", a !== undefined ? (a > 0 ? mm2(a) : "none") : "–");
  const part = stl ? f!.unsupportedArea : null;
  setText("stat-overhang-part", part !== null && part !== undefined ? (part > 0 ? mm2(part) + (s!.complete ? "" : " so far") : "none") : "–");
  const worst = stl ? f!.worstOverhang : null;
  setText("stat-overhang-worst", worst ? `${nf.format(worst.index + 1)} · ${mm2(worst.area)}` : "–");
  ($("btn-worst-overhang") as HTMLButtonElement).disabled = !worst;
  $("overhangs-hint").textContent = s?.source === "gco" ? "Overhang areas are computed for sliced parts." : "";
}

export function writeStats(page: Page): void {
  const { store } = page;
  const s = store.slice;
  const current = store.current;
  roleLabels(s?.source ?? "stl", s?.figures.fromHeader ?? false);
  const note = s?.figures.movesNote ?? null;
  $("figures-note").hidden = note === null;
  $("figures-note").textContent = note ? `Computed from the file's moves: ${note}.` : "";
  writeCalibration(page);
  $("empty").hidden = s !== null;
  if (!s) {
    writeVoids(null, current);
    writeUnit1(null, current);
    for (const id of ["stat-model", "stat-parts", "stat-size", "stat-facets", "stat-layers", "stat-droplet", "stat-outer", "stat-inner", "stat-fill", "stat-droplets", "stat-volume", "stat-mass", "stat-time", "stat-travel", "stat-z", "stat-layer-droplets"]) setText(id, "–");
    $("warnings").hidden = true;
    requestPlot();
    return;
  }
  const f = s.figures;
  setText("stat-model", s.name);
  setText("stat-parts", partsText(s));
  const b = s.info.bounds;
  if (b) setText("stat-size", `${fmtMm(b.max[0] - b.min[0])} × ${fmtMm(b.max[1] - b.min[1])} × ${fmtMm(b.max[2] - b.min[2])} mm`);
  else if (Number.isFinite(s.bbox.minX)) setText("stat-size", `${fmtMm(s.bbox.maxX - s.bbox.minX)} × ${fmtMm(s.bbox.maxY - s.bbox.minY)} mm (droplets)`);
  else setText("stat-size", "–");
  const facets = s.info.mesh?.facets_in_file;
  setText("stat-facets", facets !== undefined ? nf.format(facets) : s.source === "gco" ? "(G-code file)" : "–");
  setText("stat-layers", s.complete || s.done === s.layers ? nf.format(s.layers) : `${nf.format(s.done)} of ${nf.format(s.layers)}`);
  setText("stat-droplet", `${s.dropletWidth.toFixed(3)} × ${s.layerHeight.toFixed(3)} mm`);
  setText("stat-outer", nf.format(f.totals.outer));
  setText("stat-inner", nf.format(f.totals.inner));
  setText("stat-fill", nf.format(f.totals.fill));
  setText("stat-droplets", nf.format(f.droplets));
  const e = f.estimates;
  setText("stat-volume", e ? `${(e.volume / 1000).toFixed(2)} cm³` : "–");
  setText("stat-mass", e ? `${e.mass.toFixed(2)} g` : "–");
  setText("stat-time", e ? (s.complete ? "" : "≥ ") + duration(e.seconds) : "–");
  setText("stat-travel", `${(f.travelTotal / 1000).toFixed(2)} m`);
  $("stat-time").title = f.readNote ? `No estimate: ${f.readNote}` : "";
  const c = s.counts[current];
  setText("stat-z", s.z[current] !== undefined ? `${s.z[current].toFixed(3)} mm` : "–");
  setText("stat-layer-droplets", c ? nf.format(c.outer + c.inner + c.fill + (c.support ?? 0)) : "–");
  writeVoids(s, current);
  writeUnit1(s, current);
  const warnings = [...((s.info.warnings ?? []) as string[]), ...s.repairs];
  $("warnings").hidden = warnings.length === 0;
  const list = $("warning-list");
  const text = warnings.join("\n");
  if (list.dataset.text !== text) {
    // rebuilt only when it changes: writeStats runs many times during a slice
    list.dataset.text = text;
    list.replaceChildren(
      ...warnings.map((w) => {
        const li = document.createElement("li");
        li.textContent = w;
        return li;
      }),
    );
  }
  writeUnitFix(page, s);
  // the per-layer plot shows the same figures (and the current layer)
  requestPlot();
}

/**
 * The unit rule's fix, offered, never applied silently: when the part's size suggests the file
 * is in inches (or micrometres), a button scales x, y and z by the suggested factor and slices
 * again.
 */
function writeUnitFix(page: Page, s: Slice): void {
  const factor = s.info.suggested_scale;
  const btn = $("btn-unit-fix") as HTMLButtonElement;
  btn.hidden = typeof factor !== "number" || s.job === null || page.store.job === null;
  if (typeof factor !== "number" || btn.hidden) return;
  btn.textContent = factor > 1 ? `Scale ×${factor} (inches → mm)` : `Scale ×${factor} (µm → mm)`;
  btn.title = "Scale x, y and z by this factor and slice again";
  btn.onclick = () => page.actions.unitFix(factor);
}

/** The slice's parts as the core placed them: "gear.stl × 2, box.stl" (one line per part). */
function partsText(s: Slice): string {
  const insts = s.info.instances;
  if (!insts || insts.length === 0) return s.source === "gco" ? "–" : "1";
  const parts = new Map<number, { name: string; copies: number }>();
  for (const i of insts) parts.set(i.part, { name: i.name, copies: i.copies });
  return [...parts.values()].map((p) => (p.copies > 1 ? `${p.name} × ${p.copies}` : p.name)).join("\n");
}

/** The model's name in the header; the "open a file" hint hidden (or shown again). */
export function showModel(name: string | null): void {
  if (name !== null) $("model-name").textContent = name;
  $("empty").hidden = name !== null;
}
