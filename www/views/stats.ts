// The statistics panel: the model, droplets by role, the estimates, this layer, the mesh
// warnings and the unit fix. The figures are the core's (figures.ts); nothing is computed here.

import type { Page } from "./page";
import type { Slice } from "../core/store";
import { writeCalibration } from "./calibrate";
import { $, duration, el, nf, setText, sub, unitRows } from "./dom";
import { supportUnit, unitRole, unitSetting, unitsOf } from "../core/units";
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
  $("stat-support-label").hidden = $("stat-support").hidden = byCommand;
}

const mm2 = (x: number) => `${x < 0.1 ? x.toFixed(3) : x.toFixed(2)} mm²`;

/** The rows of units 1 … n − 1 (unit 0's are the page's markup): the legend's entry of its
 *  parts' droplets, its droplet row, its material and mass, its parts' predicted density. */
function unitRowsOf(n: number): void {
  const name = (u: number) => `Unit ${u}`;
  unitRows("legend", $("legend-support"), n, (u) => [
    el("span", { id: `legend-unit${u}`, hidden: "" }, el("i", { class: `unit${u}` }), el("span", { id: `legend-unit${u}-label` }, `Unit-${u} part`)),
  ]);
  unitRows("drops", $("stat-droplets"), n, (u) => [
    el("dt", {}, el("i", { class: `unit${u}` }), el("span", { id: `stat-unit${u}-label` }, `${name(u)}, all`)),
    el("dd", { id: `stat-unit${u}` }, "–"),
  ]);
  unitRows(
    "mass",
    $("stat-unit-times-label"),
    n,
    (u) => [
      el("dt", { id: `stat-volume${u}-label`, title: `${name(u)}'s droplets × B${sub(u)}²H` }, `Material, unit ${u}`),
      el("dd", { id: `stat-volume${u}` }, "–"),
      el("dt", { id: `stat-mass${u}-label`, title: `With ${unitSetting("material_density", u)}` }, `Mass, unit ${u}`),
      el("dd", { id: `stat-mass${u}` }, "–"),
    ],
    true,
  );
  unitRows("density", $("stat-density"), n, (u) => [
    el("dt", { id: `stat-density${u}-label`, title: `The same for the parts of unit ${u} (a ${unitRole(u)}, droplets of B${sub(u)})`, hidden: "" }, `Predicted density, unit ${u}`),
    el("dd", { id: `stat-density${u}`, hidden: "" }, "–"),
  ]);
}

/** Each unit's droplets and the support: the legend's entries, the droplet rows, the units'
 *  material, mass and time, and the overhang block. All figures are the core's (a .gco
 *  file's droplets after each `T`, as read). */
function writeUnits(s: Slice | null, current: number, n: number): void {
  const f = s?.figures;
  const units = f ? f.units(n) : [];
  const support = f?.totals.support ?? 0;
  const gco = s?.source === "gco";
  const byCommand = gco && !(f?.fromHeader ?? false);
  // the unit that prints the support (the slice's setting; unit 1 when it is off)
  const supportBy = (s && supportUnit(s.settings.support)) ?? 1;
  const supportName = n > 1 || supportBy > 1 ? `Support (unit ${supportBy})` : "Support";
  setText("stat-support-name", supportName);
  setText("legend-support-label", supportName);
  const layer = s?.cache.get(current);
  let layerSupport = 0;
  const layerParts = new Array<number>(n).fill(0);
  if (layer?.units) {
    for (let i = 0; i < layer.roles.length; i++) {
      if (layer.roles[i] === 3) layerSupport++;
      else if (layer.units[i] < n) layerParts[layer.units[i]]++;
    }
  }
  $("legend-support").hidden = !(support > 0 || layerSupport > 0);
  setText("stat-support", s ? nf.format(support) : "–");
  // one unit prints no support: its row only when a .gco file has some
  if (n === 1 && support === 0) $("stat-support-label").hidden = $("stat-support").hidden = true;
  let any = false;
  // the droplet time of unit 0 and of every other unit that prints
  const times: { unit: number; text: string }[] = [];
  for (let u = 0; u < n; u++) {
    const d = units[u];
    const parts = (d?.droplets ?? 0) - (u === supportBy ? support : 0);
    if (u === 0 || (d?.droplets ?? 0) > 0) times.push({ unit: u, text: d?.seconds !== null && d?.seconds !== undefined ? duration(d.seconds) : "–" });
    if (u === 0) continue;
    $(`legend-unit${u}`).hidden = !(parts > 0 || (layerParts[u] ?? 0) > 0);
    setText(`legend-unit${u}-label`, gco ? `Unit ${u} (after T${u})` : `Unit-${u} part`);
    setText(`stat-unit${u}-label`, byCommand ? `Unit ${u} (after T${u})` : `Unit ${u}, all`);
    setText(`stat-unit${u}`, s ? nf.format(d?.droplets ?? 0) : "–");
    const has = (d?.droplets ?? 0) > 0 && d?.volume !== null;
    any ||= has;
    for (const id of [`stat-volume${u}`, `stat-mass${u}`]) $(id).hidden = $(`${id}-label`).hidden = !has;
    if (has && d) {
      setText(`stat-volume${u}`, d.volume !== null ? `${(d.volume / 1000).toFixed(2)} cm³` : "–");
      setText(`stat-mass${u}`, d.mass !== null ? `${d.mass.toFixed(2)} g` : "–");
    }
  }
  $("unit-stats").hidden = !any;
  if (any) {
    setText("stat-unit-times-label", `Droplet time, unit ${times.map((t) => t.unit).join(" · ")}`);
    setText("stat-unit-times", times.every((t) => t.text !== "–") ? times.map((t) => t.text).join(" · ") : "–");
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
  // the units shown: the slice's, else the form's
  const n = s ? s.unitCount : unitsOf(page.form?.values());
  unitRowsOf(n);
  roleLabels(s?.source ?? "stl", s?.figures.fromHeader ?? false);
  const note = s?.figures.movesNote ?? null;
  $("figures-note").hidden = note === null;
  $("figures-note").textContent = note ? `Computed from the file's moves: ${note}.` : "";
  writeCalibration(page);
  $("empty").hidden = s !== null;
  if (!s) {
    writeVoids(null, current, n);
    writeUnits(null, current, n);
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
  writeVoids(s, current, n);
  writeUnits(s, current, n);
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
