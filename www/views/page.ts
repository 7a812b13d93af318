// What the flows and views share: the store, the worker pool, the views (as interfaces: the
// flows depend on these, not on the classes that draw), the settings form once the core's
// schema has arrived, and the actions (what the user can ask for: main.ts wires them to the
// flows, so that a view never imports a flow). main.ts makes the one instance.

import type { Pool } from "../core/client";
import type { History, Snapshot } from "../core/history";
import type { Changes } from "../core/job";
import type { ProfileKind } from "../core/profiles";
import type { CalibrateRequest, Calibration, LayerData, Orientation, Orientations } from "../core/protocol";
import type { PageInit, RawSettings, SettingName, Settings, SomeSettings } from "../core/settings";
import type { Store } from "../core/store";
import type { Bounds, Camera3D, CutView, View } from "../core/view";
import type { Line } from "../core/cutline";

export interface Page {
  readonly store: Store;
  readonly pool: Pool;
  /** The layer canvas. */
  readonly renderer: LayerCanvas;
  /** The vertical cut's canvas. */
  readonly cut: CutCanvas;
  /** The stage's 3D tab. */
  readonly view3d: View3DView;
  /** The parts panel (left column). */
  readonly parts: PartsView;
  /** What the views ask for. */
  readonly actions: Actions;
  /** Undo and redo of the job and the settings (flows/history.ts records into it). */
  readonly history: History<Snapshot>;
  /** The settings form, once init has answered. */
  form?: SettingsView;
  /** The core's version, settings schema and defaults, once init has answered. */
  init?: PageInit;
}

/** What a view asks for when the user acts (main.ts wires each to its flow). */
export interface Actions {
  /** Goes to layer `i` (clamped to the slice). */
  show(i: number): void;
  /** The part fills the layer canvas (or the 3D view frames the plate, when it is shown). */
  fit(): void;
  /** Shows an error in the page. */
  error(e: unknown): void;
  selectPart(id: number | null): void;
  editParts(edits: { id: number; changes: Changes }[]): Promise<boolean>;
  /** A dragged instance dropped `dx`, `dy` mm away: its part placed there. */
  movePart(id: number, copy: number, dx: number, dy: number): Promise<boolean>;
  layFlat(id: number): void;
  /** The part's candidate orientations, best first (the core's; throws its error). */
  orient(id: number): Promise<Orientations>;
  /** Stops the Orient under way (its promise rejects with `Cancelled`); the job stays as it
   *  was. While a slice runs, the slice is cancelled too (the job worker does both). */
  cancelOrient(): void;
  /** The part turned to `o` (one undoable part edit). */
  applyOrientation(id: number, o: Orientation): Promise<boolean>;
  /** Profiles (flows/profiles.ts): save the current settings of `kind` as `name`, use,
   *  rename, delete, export one, import a file. */
  profileSave(name: string, kind: ProfileKind, unit: number): void;
  /** `unit`: the unit a material profile of one material is for. */
  profileUse(name: string, unit: number): void;
  profileRename(name: string, to: string): void;
  profileDelete(name: string): void;
  profileExport(name: string): void;
  profileImport(file: File): void;
  duplicatePart(id: number): void;
  removePart(id: number): void;
  arrangeAll(): void;
  saveJob(): void;
  /** The unit fix: the parts scaled by `factor` and the job sliced again. */
  unitFix(factor: number): void;
  /** The droplet calibration for a mass and a density (a worker computes it). */
  calibrate(request: CalibrateRequest): Promise<Calibration>;
  /** The display meshes the 3D view lacks are fetched (only while it is shown). */
  meshes(): void;
  /** The 3D tint's threshold (the face normal's z) for `settings`. */
  overhangFace(settings: SomeSettings): Promise<number>;
  /** The cut line set (null: no cut); `refit` fits the cut's canvas to it. */
  setCutLine(line: Line | null, refit: boolean): void;
  /** Keeps the cut in step with the page (a new slice, layers that arrived, the layer shown). */
  updateCut(): void;
  /** The cut line shown (null: no cut). */
  cutLine(): Line | null;
  undo(): void;
  redo(): void;
  /** The settings form was set by a view (not typed): recorded for undo and remembered. */
  settingsEdited(): void;
}

/** The zoom and pan a canvas has for what it shows. */
export interface PanZoom {
  readonly canvas: HTMLCanvasElement;
  zoomAt(px: number, py: number, factor: number): void;
  panBy(dxPx: number, dyPx: number): void;
}

/** One layer of the cut: what the page or the core found along the line. */
export interface CutLayer {
  /** t, d (mm) and role per droplet whose footprint the plane crosses. */
  near: Float64Array;
  /** The part's region along the line: t0, t1 per span (from the core; null until then). */
  spans: Float64Array | null;
  /** The 3D estimate's voids: band, t0, t1 per void (from the core; null until then). */
  voids: Float64Array | null;
}

/** The layer canvas (views/canvas/render.ts). */
export interface LayerCanvas extends PanZoom {
  /** The view, kept within the limits (set it as a whole). */
  view: View;
  current: LayerData | null;
  below: LayerData | null;
  dropletWidth: number;
  showTravel: boolean;
  showBelow: boolean;
  showVoids: boolean;
  /** Per droplet of `current`, 1 when it breaks the overhang rule; null while unknown or off. */
  overhangs: Uint8Array | null;
  showOverhangs: boolean;
  /** Called after every draw. */
  onDraw: (() => void) | null;
  fit(b: Bounds | null): void;
  request(): void;
  /** Draws now (synchronously, sized first): the tests' hook. */
  drawNow(): void;
  toMm(px: number, py: number): [number, number];
  toPx(x: number, y: number): [number, number];
}

/** The vertical cut's canvas (views/canvas/cutrender.ts). */
export interface CutCanvas extends PanZoom {
  layers: Map<number, CutLayer>;
  z: number[];
  layerHeight: number;
  radius: number;
  length: number;
  current: number;
  showVoids: boolean;
  /** The user zoomed or panned (a resize keeps the view). */
  touched: boolean;
  fit(): void;
  request(): void;
  /** Draws now (synchronously, sized first): the tests' hook. */
  drawNow(): void;
  cutView(): CutView;
  setView(v: CutView): void;
}

/** The stage's 3D tab (views/view3d/panel.ts). */
export interface View3DView {
  /** Whether the 3D tab is shown (else the layer canvas). */
  readonly active: boolean;
  setActive(on: boolean): void;
  /** Shows the page's job, its selection and the slice's layer. */
  sync(page: Page): void;
  fit(): void;
  /** The camera (plate mm), null before the view was made. */
  camera(): Camera3D | null;
  /** Puts the camera there (kept until the view is made and has framed its job). */
  setCamera(c: Camera3D): void;
  /** For the tests: the view's state after a synchronous draw (null before it was made). */
  testState(): object | null;
}

/** The parts panel (views/parts.ts). */
export interface PartsView {
  /** Wires the panel's inputs and buttons (once). */
  wire(): void;
  /** Redraws the list and the editor from the job. */
  render(): void;
}

/** The settings form (views/form.ts). */
export interface SettingsView {
  /** Every setting as the form holds it (a field in error keeps its last good value). */
  values(): Settings;
  get<K extends SettingName>(name: K): Settings[K];
  /** Sets the values given. */
  set(values: SomeSettings): void;
  /** Sets values from outside (a job file's, a link's, a .gco header's: any names); returns
   *  the names it did not know (ignored). */
  setRaw(values: RawSettings): string[];
  reset(): void;
  errors(): { name: string; message: string }[];
  focusFirstError(): void;
  /** Shows the settings of units 0 … n − 1 only (the groups "Unit N" of the others hidden). */
  showUnits(n: number): void;
}
