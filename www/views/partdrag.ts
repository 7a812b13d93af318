// Moving a part in the layer view: the selected part's instances are outlined on the layer
// canvas (their boxes on the plate, from the core's layout), and a drag that starts inside one
// of them moves the part (the outline follows; on release the part is placed there and the core
// lays the job out again). Elsewhere, or with no part selected, a drag pans as before. The
// droplets drawn stay the slice's until the job is sliced again (the Slice button says so).
// Instances off the plate are outlined in the warning colour, selected or not.

import { jobOffPlate } from "../core/plate";
import type { Page } from "./page";
import { $ } from "./dom";

interface Drag {
  pointerId: number;
  part: number;
  copy: number;
  from: [number, number];
  dx: number;
  dy: number;
}

let drag: Drag | null = null;

/** The instance boxes to outline (plate mm): [copy, minX, minY, maxX, maxY, off the plate,
 *  part id] of the selected part's instances and of every instance off the plate. */
function boxes(page: Page): [number, number, number, number, number, boolean, number][] {
  const job = page.store.job;
  if (!job?.layout) return [];
  const off = new Set(jobOffPlate(job, page.form?.values()).map((o) => `${o.part}:${o.copy}`));
  return job.layout.instances
    .filter((i) => job.parts[i.part]?.id === job.selected || off.has(`${i.part}:${i.copy}`))
    .map((i) => [i.copy, i.min[0], i.min[1], i.max[0], i.max[1], off.has(`${i.part}:${i.copy}`), job.parts[i.part].id]);
}

function drawBoxes(page: Page): void {
  const list = boxes(page);
  const r = page.renderer;
  const off = list.filter((b) => b[5]).length;
  r.canvas.dataset.offPlate = String(off);
  $("legend-off").hidden = off === 0;
  if (list.length === 0) return;
  const ctx = r.canvas.getContext("2d");
  if (!ctx) return;
  const dpr = window.devicePixelRatio || 1;
  ctx.save();
  ctx.setTransform(1, 0, 0, 1, 0, 0);
  for (const [copy, x0, y0, x1, y1, off, id] of list) {
    const moving = drag && drag.copy === copy && drag.part === id;
    const [ox, oy] = moving ? [drag!.dx, drag!.dy] : [0, 0];
    const [ax, ay] = r.toPx(x0 + ox, y1 + oy).map((v) => v * dpr);
    const [bx, by] = r.toPx(x1 + ox, y0 + oy).map((v) => v * dpr);
    const rgb = off ? "224, 49, 49" : "28, 126, 214";
    ctx.fillStyle = `rgba(${rgb}, ${moving ? 0.12 : off ? 0.1 : 0.05})`;
    ctx.fillRect(ax, ay, bx - ax, by - ay);
    ctx.strokeStyle = off ? "#e03131" : "#1c7ed6";
    ctx.lineWidth = (off ? 2 : 1.5) * dpr;
    ctx.setLineDash(off ? [] : [6 * dpr, 4 * dpr]);
    ctx.strokeRect(ax, ay, bx - ax, by - ay);
  }
  ctx.restore();
}

/** The outline and the drag (after wireLayerView and wireCut: it runs before the pan). */
export function wirePartDrag(page: Page): void {
  const { renderer } = page;
  const canvas = renderer.canvas;
  const prevDraw = renderer.onDraw;
  renderer.onDraw = () => {
    prevDraw?.();
    drawBoxes(page);
  };
  const at = (ev: PointerEvent): [number, number] => {
    const r = canvas.getBoundingClientRect();
    return renderer.toMm(ev.clientX - r.left, ev.clientY - r.top);
  };
  canvas.addEventListener(
    "pointerdown",
    (ev) => {
      if (ev.button !== 0 || $("btn-cut").getAttribute("aria-pressed") === "true") return;
      const job = page.store.job;
      const [x, y] = at(ev);
      const hit = boxes(page).find(([, x0, y0, x1, y1, , id]) => id === job?.selected && x >= x0 && x <= x1 && y >= y0 && y <= y1);
      if (!job || job.selected === null || !hit) return;
      ev.stopImmediatePropagation();
      drag = { pointerId: ev.pointerId, part: job.selected, copy: hit[0], from: [x, y], dx: 0, dy: 0 };
      canvas.setPointerCapture(ev.pointerId);
      canvas.classList.add("dragging");
    },
    { capture: true },
  );
  canvas.addEventListener(
    "pointermove",
    (ev) => {
      if (!drag || ev.pointerId !== drag.pointerId) return;
      ev.stopImmediatePropagation();
      const [x, y] = at(ev);
      drag.dx = x - drag.from[0];
      drag.dy = y - drag.from[1];
      renderer.request();
    },
    { capture: true },
  );
  const end = (ev: PointerEvent) => {
    if (!drag || ev.pointerId !== drag.pointerId) return;
    const d = drag;
    drag = null;
    canvas.classList.remove("dragging");
    if (ev.type === "pointerup" && Math.hypot(d.dx, d.dy) > 1e-6) {
      void page.actions.movePart(d.part, d.copy, d.dx, d.dy).then(() => renderer.request());
    } else renderer.request();
  };
  canvas.addEventListener("pointerup", end, { capture: true });
  canvas.addEventListener("pointercancel", end, { capture: true });
}
