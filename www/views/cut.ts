// The vertical cut's line on the layer view (the "Cut" tool: drag a line across the part, drag
// its ends or the line to move it; or "x =" / "y =" a position), drawn on the layer canvas, and
// the cut panel around the section (canvas/cutrender.ts draws it). The section's runs of the
// workers: flows/cut.ts (through the page's actions).

import { checkLine, cutLabel, lineLength, type Line, type Pt } from "../core/cutline";
import type { Page } from "./page";
import { wirePanZoom } from "./canvas/panzoom";
import { $, el, unitRows } from "./dom";
import { unitsOf } from "../core/units";

/** Pointer distance (CSS px) that grabs an end or the line. */
const GRAB_PX = 9;

/** The line drawn (while it is dragged, where the pointer has it); null: no cut. */
let drawn: Line | null = null;
/** The "Cut" tool: a drag on the layer canvas draws a new line. */
let tool = false;
let timer = 0;

/** Sets the cut line (null: no cut) and shows the cut panel; the section follows. */
export function setLine(page: Page, line: Line | null, refit = true): void {
  drawn = line;
  $("cut-panel").hidden = !line;
  writeCutLegend(page.store.slice?.unitCount ?? unitsOf(page.form?.values()));
  writePosition(line);
  page.renderer.request();
  page.actions.setCutLine(line, refit);
}

/** The legend's entries of units 1 … n − 1 (their parts' droplets; unit 0's are by role). */
export function writeCutLegend(n: number): void {
  unitRows("cut", $("cut-legend-support"), n, (u) => [el("span", {}, el("i", { class: `unit${u}` }), `Unit ${u}`)]);
}

/** The cut's status line: the line's length, then `more` (the section's progress); `missed`:
 *  the line crosses no part, said over the (empty) section. */
export function writeCutStatus(more: string, missed = false): void {
  $("cut-status").textContent = (drawn ? `${lineLength(drawn).toFixed(1)} mm` : "") + more;
  $("cut-missed").hidden = !missed;
}

/** The position field shows where the line is: "y =" its middle's y for a line more along x,
 *  else "x =" its middle's x (an axis line's own position; a slanted one's middle). */
function writePosition(line: Line | null): void {
  if (!line) return;
  $("cut-where").textContent = `Section along ${cutLabel(line)}, from A to B`;
  const across = Math.abs(line.b[0] - line.a[0]) >= Math.abs(line.b[1] - line.a[1]) ? "y" : "x";
  const k = across === "y" ? 1 : 0;
  $<HTMLSelectElement>("cut-axis").value = across;
  $<HTMLInputElement>("cut-pos").value = String(Math.round(((line.a[k] + line.b[k]) / 2) * 100) / 100);
}

/** The line a little longer than the part, through `v` on the other axis. */
function axisLine(page: Page, axis: "x" | "y", v: number): Line | null {
  const s = page.store.slice;
  if (!s || !Number.isFinite(v)) return null;
  const b = s.info.bounds ? { minX: s.info.bounds.min[0], maxX: s.info.bounds.max[0], minY: s.info.bounds.min[1], maxY: s.info.bounds.max[1] } : s.bbox;
  if (!(b.maxX >= b.minX)) return null;
  const m = 1;
  return checkLine(axis === "y" ? { a: [b.minX - m, v], b: [b.maxX + m, v] } : { a: [v, b.minY - m], b: [v, b.maxY + m] });
}

/** The line on the layer canvas (after every draw of it), with its ends as handles. */
function drawOnLayer(page: Page): void {
  const l = drawn;
  const r = page.renderer;
  if (!l) {
    delete r.canvas.dataset.cutLabel;
    return;
  }
  const ctx = r.canvas.getContext("2d");
  if (!ctx) return;
  const dpr = window.devicePixelRatio || 1;
  const [ax, ay] = r.toPx(l.a[0], l.a[1]).map((v) => v * dpr);
  const [bx, by] = r.toPx(l.b[0], l.b[1]).map((v) => v * dpr);
  ctx.save();
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  ctx.lineCap = "round";
  ctx.strokeStyle = "rgba(255, 255, 255, 0.9)";
  ctx.lineWidth = 5 * dpr;
  ctx.beginPath();
  ctx.moveTo(ax, ay);
  ctx.lineTo(bx, by);
  ctx.stroke();
  ctx.strokeStyle = "#1c2430";
  ctx.lineWidth = 1.8 * dpr;
  ctx.setLineDash([8 * dpr, 5 * dpr]);
  ctx.stroke();
  ctx.setLineDash([]);
  for (const [x, y, name] of [[ax, ay, "A"], [bx, by, "B"]] as const) {
    ctx.fillStyle = "#fff";
    ctx.strokeStyle = "#1c2430";
    ctx.lineWidth = 1.8 * dpr;
    ctx.beginPath();
    ctx.arc(x, y, 6 * dpr, 0, 2 * Math.PI);
    ctx.fill();
    ctx.stroke();
    ctx.fillStyle = "#1c2430";
    ctx.font = `600 ${11 * dpr}px system-ui, sans-serif`;
    ctx.textBaseline = "bottom";
    ctx.fillText(name, x + 8 * dpr, y - 6 * dpr);
  }
  // where it is, beside the line's middle (on a white ground; the canvas' attribute for tests)
  const label = cutLabel(l);
  r.canvas.dataset.cutLabel = label;
  ctx.font = `600 ${12 * dpr}px system-ui, sans-serif`;
  ctx.textBaseline = "top";
  const w = ctx.measureText(label).width;
  const mx = Math.min(Math.max((ax + bx) / 2 + 8 * dpr, 4 * dpr), r.canvas.width - w - 8 * dpr);
  const my = Math.min(Math.max((ay + by) / 2 + 8 * dpr, 4 * dpr), r.canvas.height - 22 * dpr);
  ctx.fillStyle = "rgba(255, 255, 255, 0.88)";
  ctx.fillRect(mx - 4 * dpr, my - 3 * dpr, w + 8 * dpr, 18 * dpr);
  ctx.fillStyle = "#1c2430";
  ctx.fillText(label, mx, my);
  ctx.restore();
}

/** What a pointer at CSS px (x, y) grabs: an end, the line, or nothing. */
function grab(page: Page, x: number, y: number): "a" | "b" | "line" | null {
  const l = drawn;
  if (!l) return null;
  const r = page.renderer;
  const a = r.toPx(l.a[0], l.a[1]);
  const b = r.toPx(l.b[0], l.b[1]);
  if (Math.hypot(x - a[0], y - a[1]) <= GRAB_PX) return "a";
  if (Math.hypot(x - b[0], y - b[1]) <= GRAB_PX) return "b";
  const dx = b[0] - a[0];
  const dy = b[1] - a[1];
  const len2 = dx * dx + dy * dy;
  const u = len2 > 0 ? Math.max(0, Math.min(1, ((x - a[0]) * dx + (y - a[1]) * dy) / len2)) : 0;
  return Math.hypot(x - a[0] - u * dx, y - a[1] - u * dy) <= GRAB_PX / 1.5 ? "line" : null;
}

function setTool(page: Page, on: boolean): void {
  tool = on;
  const btn = $("btn-cut");
  btn.setAttribute("aria-pressed", String(on));
  btn.classList.toggle("active", on);
  page.renderer.canvas.classList.toggle("cutting", on);
}

/** The tool, the numeric position, the line on the layer canvas, the cut canvas' zoom and pan. */
export function wireCut(page: Page): void {
  const { renderer, cut, actions } = page;
  const prevDraw = renderer.onDraw;
  renderer.onDraw = () => {
    prevDraw?.();
    drawOnLayer(page);
    if (drawn) {
      cut.current = page.store.current;
      // a new slice, new layers or another layer shown: later, not inside the layer's draw
      clearTimeout(timer);
      timer = window.setTimeout(() => actions.updateCut(), 30);
    }
  };

  // a slice that completed (or layers that arrived) while the layer canvas was not redrawn
  let seen = "";
  setInterval(() => {
    const s = page.store.slice;
    const now = s && drawn ? `${s.done}/${s.complete}/${page.store.current}/${s.cache.size}` : "";
    if (now !== seen) {
      seen = now;
      if (now) actions.updateCut();
    }
  }, 400);

  $("btn-cut").addEventListener("click", () => {
    setTool(page, !tool);
    const s = page.store.slice;
    if (tool && !drawn && s) {
      const b = s.info.bounds;
      const y = b ? (b.min[1] + b.max[1]) / 2 : (s.bbox.minY + s.bbox.maxY) / 2;
      setLine(page, axisLine(page, "y", y));
    }
  });
  $("cut-close").addEventListener("click", () => {
    setTool(page, false);
    setLine(page, null);
  });
  $("cut-fit").addEventListener("click", () => cut.fit());
  $<HTMLInputElement>("cut-voids").addEventListener("change", (ev) => {
    cut.showVoids = (ev.target as HTMLInputElement).checked;
    cut.request();
  });
  const position = () => {
    const axis = $<HTMLSelectElement>("cut-axis").value === "x" ? "x" : "y";
    const l = axisLine(page, axis, Number($<HTMLInputElement>("cut-pos").value));
    if (l) setLine(page, l);
  };
  $("cut-apply").addEventListener("click", position);
  $("cut-pos").addEventListener("keydown", (ev) => {
    if ((ev as KeyboardEvent).key === "Enter") position();
  });

  // on the layer canvas: grab an end or the line, or (the tool) draw a new line; before the
  // layer view's pan (capture), which never sees a pointer the cut took
  const canvas = renderer.canvas;
  let drag: { what: "a" | "b" | "line"; id: number; from: Pt; line: Line; fresh: boolean } | null = null;
  const at = (ev: PointerEvent): [number, number] => {
    const r = canvas.getBoundingClientRect();
    return [ev.clientX - r.left, ev.clientY - r.top];
  };
  canvas.addEventListener(
    "pointerdown",
    (ev) => {
      if (!page.store.slice) return;
      const [x, y] = at(ev);
      let what = grab(page, x, y);
      const mm = renderer.toMm(x, y);
      const fresh = !what && tool;
      if (fresh) {
        drawn = { a: mm, b: mm };
        what = "b";
      }
      if (!what || !drawn) return;
      ev.stopImmediatePropagation();
      drag = { what, id: ev.pointerId, from: mm, line: { a: [...drawn.a], b: [...drawn.b] }, fresh };
      canvas.setPointerCapture(ev.pointerId);
    },
    { capture: true },
  );
  canvas.addEventListener(
    "pointermove",
    (ev) => {
      if (!drag || ev.pointerId !== drag.id) {
        if (!drag && drawn) canvas.classList.toggle("grab", grab(page, ...at(ev)) !== null);
        return;
      }
      ev.stopImmediatePropagation();
      const [x, y] = renderer.toMm(...at(ev));
      const l = drag.line;
      const dx = x - drag.from[0];
      const dy = y - drag.from[1];
      const next: Line =
        drag.what === "a" ? { a: [x, y], b: l.b } : drag.what === "b" ? { a: l.a, b: [x, y] } : { a: [l.a[0] + dx, l.a[1] + dy], b: [l.b[0] + dx, l.b[1] + dy] };
      drawn = next;
      renderer.request();
    },
    { capture: true },
  );
  const end = (ev: PointerEvent) => {
    if (!drag || ev.pointerId !== drag.id) return;
    ev.stopImmediatePropagation();
    const fresh = drag.fresh;
    drag = null;
    const l = checkLine(drawn);
    if (l) setLine(page, l, fresh || $("cut-panel").hidden === true);
    else setLine(page, null);
  };
  canvas.addEventListener("pointerup", end, { capture: true });
  canvas.addEventListener("pointercancel", end, { capture: true });

  // the cut canvas: wheel zoom, drag pan, double-click fit
  wirePanZoom(cut, () => cut.fit());
}
