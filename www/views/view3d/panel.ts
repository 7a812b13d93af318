// The stage's 3D tab: the plate and every instance of the build job (view3d.ts), from the
// parts' display meshes and the core's layout matrices (one View3DPart per instance, id
// `${part id}:${copy}`); after a slice of the job as it is, cut at the layer the slider shows.
// A click selects the part in the parts panel; dragging an instance moves its part (re-laid
// out by the core on release). The toggle "Layer | 3D" switches the stage between the layer
// canvas and this view; the View3D (a WebGL context) is made the first time the tab is opened,
// and its code (view3d.ts with three.js, most of the page's script) is loaded then: a chunk
// of its own (dynamic import; scripts/build.sh splits the bundle), precached by the service
// worker like the rest of the page.

import { jobSettings } from "../../core/job";
import type { Settings } from "../../core/settings";
import { supportColumns } from "../../core/supportcolumns";
import { jobOffPlate } from "../../core/plate";
import { errorBanner } from "../banner";
import { openPartMenu, openSelectedPartMenu } from "../contextmenu";
import { $, el, unitRows } from "../dom";
import { unitsOf } from "../../core/units";
import type { Page, View3DView } from "../page";
import type { Camera3D } from "../../core/view";
import type { View3D, View3DPart, View3DSlice } from "./view3d";

/** The 3D view's id of an instance, and back. */
export const instanceId = (part: number, copy: number) => `${part}:${copy}`;

/** The instance of an id made by [[instanceId]] (null for anything else). */
export function parseInstanceId(id: string): { part: number; copy: number } | null {
  const m = /^(\d+):(\d+)$/.exec(id);
  return m ? { part: Number(m[1]), copy: Number(m[2]) } : null;
}

export class View3DPanel implements View3DView {
  private view: View3D | null = null;
  /** Whether the view's code was asked for (it loads once; the view is made when it is in). */
  private loading = false;
  private parts: View3DPart[] = [];
  private plate = { x: 154, y: 134, z: 0 };
  private slice: View3DSlice | null = null;
  /** The slice's support as boxes (core/supportcolumns.ts), and the boxes the view has. */
  private support: Float32Array | null = null;
  private shownSupport: Float32Array | null = null;
  private selected: string | null = null;
  /** The job shown, and the one the camera was last fitted to: a new job is framed once
   *  (editing or slicing it again keeps the camera). */
  private model: unknown = null;
  private framed: unknown = null;
  private page: Page | null = null;
  /** The overhang tint: the core's threshold for the settings `overhangFor` (null: off, or
   *  not known yet). */
  private overhang: number | null = null;
  private overhangFor = "";
  /** A camera asked for (a link's) before the view could take it: set after its first fit. */
  private wantCamera: Camera3D | null = null;
  active = false;

  constructor(private readonly container: HTMLElement) {}

  /** Shows the page's job: its instances where the core's layout puts them, the plate of the
   *  form's settings, and the slice's layers when the slice is of the job as it is now. */
  sync(page: Page): void {
    this.page = page;
    const { store } = page;
    const job = store.job;
    const layout = job?.layout;
    const parts: View3DPart[] = [];
    const values = page.form?.values();
    const off = new Set(jobOffPlate(job, values).map((o) => `${o.part}:${o.copy}`));
    if (job && layout) {
      for (const inst of layout.instances) {
        const p = job.parts[inst.part];
        const mesh = p ? job.meshOf(p) : null;
        if (!p || !mesh) continue;
        const warn = off.has(`${inst.part}:${inst.copy}`);
        parts.push({ id: instanceId(p.id, inst.copy), name: inst.name, positions: mesh.positions, matrix: inst.matrix, unit: inst.unit, warn });
      }
    }
    this.parts = parts;
    this.model = job && parts.length ? job : null;
    $("legend3d-off").hidden = off.size === 0;
    // an entry per unit but unit 0 whose parts the job has, in that unit's colour
    const n = Math.max(unitsOf(values), ...parts.map((p) => (p.unit ?? 0) + 1));
    unitRows("3d", $("legend3d-part"), n, (u) => [el("span", { id: `legend3d-unit${u}`, hidden: "" }, el("i", { class: `part${u}` }), `Unit ${u} part`)]);
    for (let u = 1; u < n; u++) $(`legend3d-unit${u}`).hidden = !parts.some((p) => p.unit === u);
    const px = Number(values?.plate_x);
    const py = Number(values?.plate_y);
    const pz = Number(values?.plate_z);
    if (px > 0 && py > 0 && Number.isFinite(px + py)) this.plate = { x: px, y: py, z: pz >= 0 && Number.isFinite(pz) ? pz : 0 };
    this.syncOverhang(page, values);
    const s = store.slice;
    const current = job && values && s?.source === "stl" && s.key === job.key(jobSettings(values));
    this.slice = current && s.layers > 0 && s.layerHeight > 0 ? { layerHeight: s.layerHeight, layers: s.layers, current: store.current } : null;
    // the support hides the overhanging faces under it: not drawn while they are tinted
    this.support = this.slice && s && !page.renderer.showOverhangs ? supportColumns(s) : null;
    // the selected part's instance clicked last stays tinted, else its first copy
    const sel = job?.selected ?? null;
    const keep = this.selected !== null && parts.some((p) => p.id === this.selected) && parseInstanceId(this.selected)?.part === sel;
    if (!keep) this.selected = sel === null ? null : (parts.find((p) => parseInstanceId(p.id)?.part === sel)?.id ?? null);
    this.apply();
  }

  /** With the overhang overlay on, the core's threshold for the form's settings (asked again
   *  when they change: the core knows which of them it reads). */
  private syncOverhang(page: Page, values: Settings | undefined): void {
    if (!page.renderer.showOverhangs || !values || !page.form || page.form.errors().length) {
      this.overhang = null;
      this.overhangFor = "";
      return;
    }
    const settings = jobSettings(page.form.values());
    const key = JSON.stringify(settings);
    if (key === this.overhangFor) return;
    this.overhangFor = key;
    this.overhang = null;
    page.actions
      .overhangFace(settings)
      .then((z) => {
        if (this.overhangFor !== key) return;
        this.overhang = z;
        this.apply();
      })
      .catch(() => {
        // a refused setting is shown by the form; the tint stays off
        if (this.overhangFor === key) this.overhangFor = "";
      });
  }

  private apply(): void {
    const v = this.view;
    if (!v) return;
    v.setPlate(this.plate.x, this.plate.y, this.plate.z);
    v.setParts(this.parts);
    v.setSlice(this.slice);
    if (this.support !== this.shownSupport) {
      this.shownSupport = this.support;
      v.setSupport(this.support);
    }
    $("legend3d-support").hidden = !this.support?.length;
    v.select(this.selected);
    v.setOverhang(this.overhang);
    if (this.model !== null && this.model !== this.framed) {
      this.framed = this.model;
      v.fit();
      // once more after the canvas took its size (a view made just now is resized later)
      requestAnimationFrame(() => {
        v.fit();
        this.takeCamera();
      });
    }
    this.takeCamera();
    $("view3d-empty").hidden = this.parts.length > 0 || this.page?.store.job !== null;
  }

  /** Layer canvas or 3D view. */
  setActive(on: boolean): void {
    const shown = on && !this.active;
    this.active = on;
    $("canvas-wrap").dataset.mode = on ? "3d" : "layer";
    $("mode-layer").setAttribute("aria-pressed", String(!on));
    $("mode-3d").setAttribute("aria-pressed", String(on));
    this.container.hidden = !on;
    // the parts' display meshes are fetched only while the view is shown
    if (shown) this.page?.actions.meshes();
    if (on && !this.loading) {
      this.loading = true;
      import("./view3d").then(
        ({ View3D }) => this.create(View3D),
        (e: unknown) => {
          this.loading = false; // asked again the next time the tab is opened
          errorBanner(new Error(`The 3D view could not be loaded (${e instanceof Error ? e.message : String(e)}). Reload the page to try again.`));
        },
      );
    }
  }

  /** The view, made once its code is in (the tab may have been left meanwhile: it is made
   *  all the same, hidden with its container). */
  private create(Ctor: typeof View3D): void {
    const view = new Ctor(this.container);
    this.view = view;
    view.onSelect((id) => {
      const page = this.page;
      if (!page) return;
      this.selected = id;
      const at = id === null ? null : parseInstanceId(id);
      page.actions.selectPart(at ? at.part : null);
    });
    view.onMenu((id, x, y) => {
      const page = this.page;
      if (!page) return;
      const canvas = () => this.container.querySelector("canvas");
      if (id === null) {
        const c = canvas();
        if (c) openSelectedPartMenu(page, c);
        return;
      }
      const at = parseInstanceId(id);
      if (!at) return;
      this.selected = id;
      openPartMenu(page, at.part, x, y, canvas);
    });
    view.onDrag((id, dx, dy, done) => {
      const page = this.page;
      const at = parseInstanceId(id);
      if (!done || !page || !at) return;
      this.selected = id;
      page.actions.selectPart(at.part);
      if (Math.hypot(dx, dy) < 1e-6) return;
      // refused (off the plate is allowed; a value out of range is not): back where it was
      void page.actions.movePart(at.part, at.copy, dx, dy).then((ok) => ok || this.sync(page));
    });
    this.apply();
  }

  fit(): void {
    this.view?.fit();
  }

  camera(): Camera3D | null {
    return this.view?.pose() ?? this.wantCamera;
  }

  setCamera(c: Camera3D): void {
    this.wantCamera = c;
    this.takeCamera();
  }

  /** The camera asked for, once the view has framed its job (a later fit would undo it). */
  private takeCamera(): void {
    const c = this.wantCamera;
    if (!c || !this.view || this.model === null || this.model !== this.framed) return;
    this.view.setPose(c);
    // the frame after a first fit fits again: the camera is set after it
    requestAnimationFrame(() => {
      if (this.wantCamera === c) {
        this.view?.setPose(c);
        this.wantCamera = null;
      }
    });
  }

  /** For the tests: the view's state and a synchronous draw (null before the tab was opened
   *  and while the view's code is loading). */
  testState(): ReturnType<View3D["state"]> | null {
    this.view?.renderNow();
    return this.view?.state() ?? null;
  }
}

/** The toggle's buttons and the 3D view's double-click fit. */
export function wireView3D(page: Page): void {
  $("mode-layer").addEventListener("click", () => page.view3d.setActive(false));
  $("mode-3d").addEventListener("click", () => page.view3d.setActive(true));
  $("view3d").addEventListener("dblclick", () => page.view3d.fit());
}
