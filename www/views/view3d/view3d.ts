// The 3D view of the build plate and its parts (three.js, WebGL2). A self-contained class the
// page drives; it knows nothing of the store, the workers or the DOM around its container.
//
// API (kept stable for the build-job parts panel):
//   new View3D(container)        a canvas filling `container`, resized with it (ResizeObserver)
//   setPlate(x, y, z)            the plate [0,x]×[0,y] at z = 0 (mm), a 10 mm grid, its outline,
//                                the build chamber's height z (a faint box; 0: none)
//   setParts(parts)              the parts; geometry cached by id (same id + same positions
//                                array => no re-upload), matrices applied
//   setMatrix(id, matrix)        a cheap move (16 numbers, column-major, model -> plate, mm)
//   select(id | null)            the selected part is tinted (no callback)
//   onSelect(cb)                 a click (press and release within a few pixels) on a part, or
//                                on empty space (null); the view selects it before calling cb
//   onMenu(cb)                   a right-click (press and release within a few pixels: a
//                                right drag pans) on a part: cb(id, clientX, clientY), the
//                                view selects it first; the Menu key or Shift+F10 on the
//                                canvas: cb(null, …) at its middle (the owner picks the part)
//   onDrag(cb)                   with a listener, a left drag that starts on a part moves it on
//                                the plate plane: cb(id, dx, dy, done) with dx, dy the plate
//                                millimetres from the drag's start (cumulative); the view moves
//                                the part itself meanwhile (its matrix at the start, translated),
//                                and the owner's setMatrix (at any time) overrides that. Without
//                                a listener parts are not draggable and a drag orbits.
//   setSlice(s | null)           the layer stack up to layer s.current: parts clipped at that
//                                layer's top (s.top, default (current + 1) · layerHeight), the
//                                cut drawn as a solid cap (back faces in the cut colour), the
//                                current layer's slab highlighted; null = whole parts
//   fit()                        an iso-like camera framing the plate and the parts
//   pose() / setPose(c)          the camera's position and target (plate mm)
//   dispose()                    frees the GPU resources, the listeners and the canvas
// Extensions (documented here, used by the page and its tests):
//   renderNow()                  draws at once (the view otherwise draws on demand, in the next
//                                animation frame after a change, and never when idle)
//   state()                      {parts, selected, slice, overhang, frames, width, height} for
//                                the tests
//   setOverhang(z | null)        tints the faces whose unit normal (plate coordinates) has
//                                z < −z (overhanging: the core's `overhang_face_normal_z` for
//                                the job's settings); null = no tint
//   setSupport(boxes | null)     the support's boxes (support3d.ts), clipped at the layer's top
//
// Input is checked (finite numbers, lengths, bounds): bad input throws an Error naming what is
// wrong. Per frame nothing is allocated and nothing is O(triangles) but the GPU's draw: a part
// is one non-indexed BufferGeometry (flat normals) uploaded once, drawn by up to three meshes
// sharing it (body, current-layer slab, cut cap) with clipping planes.

import {
  AmbientLight,
  BackSide,
  BufferAttribute,
  BufferGeometry,
  Color,
  DirectionalLight,
  FrontSide,
  Group,
  HemisphereLight,
  type Intersection,
  Matrix4,
  Mesh,
  MeshBasicMaterial,
  MeshStandardMaterial,
  Object3D,
  PerspectiveCamera,
  Plane,
  Raycaster,
  Scene,
  SRGBColorSpace,
  Vector2,
  Vector3,
  WebGLRenderer,
  Box3,
} from "three";
import { OrbitControls } from "three/examples/jsm/controls/OrbitControls.js";
import type { Camera3D } from "../../core/view";
import { disposeObject, plateObjects } from "./plate3d";
import { showSupport } from "./support3d";
import { MAX_UNITS, UNIT_COLORS_3D } from "../../core/units";

export interface View3DPart {
  id: string;
  name: string;
  /** 9 floats per triangle, the part's model coordinates in mm. */
  positions: Float32Array;
  /** 16 numbers, column-major, model -> plate coordinates (mm), z up. */
  matrix: number[];
  /** The discharge unit printing the part (0 … MAX_UNITS − 1; each in its colour,
   *  core/units.ts `UNIT_COLORS_3D`). */
  unit?: number;
  /** Off the plate: drawn in the warning colour. */
  warn?: boolean;
}

export interface View3DSlice {
  layerHeight: number;
  layers: number;
  current: number;
  /** The current layer's top (mm); (current + 1) · layerHeight when absent. */
  top?: number;
}

/** Colours of the view (sRGB). */
export const COLORS = {
  background: 0xeef1f5,
  plate: 0xfbfcfd,
  grid: 0xdde2e9,
  gridMajor: 0xc5cdd7,
  outline: 0x7d8a99,
  /** Parts of unit 0. */
  part: UNIT_COLORS_3D[0],
  /** Overhanging faces (the layer view's overhang overlay colour). */
  overhang: 0xe8107a,
  selected: 0x1c7ed6,
  warn: 0xe03131, // a part off the plate
  /** The current layer's slab (the outer-loop colour of the layer view). */
  slab: 0xe8590c,
  /** The cut through the parts at the current layer's top. */
  cap: 0xf4b37e,
} as const;

/** Plates up to this size (mm) are drawn (the settings allow up to 100 m). */
const PLATE_MAX = 100_000;
/** A press and release this close together (px) is a click, not a drag. */
const CLICK_PX = 4;
/** A clipping plane's constant far beyond any part: nothing clipped. */
const NO_CLIP = 1e9;

interface Entry {
  id: string;
  part: View3DPart;
  positions: Float32Array;
  geometry: BufferGeometry;
  group: Group;
  body: Mesh;
  slab: Mesh;
  cap: Mesh;
  unit: number;
}

interface Press {
  pointerId: number;
  x: number;
  y: number;
  /** The part under the press (only looked up at press time when parts are draggable). */
  id: string | null;
  dragging: boolean;
  /** The plate point grabbed, and the height of the drag plane. */
  origin: Vector3;
  start: Matrix4;
  dx: number;
  dy: number;
}

function checkMatrix(m: unknown, what: string): number[] {
  if (!Array.isArray(m) || m.length !== 16 || !m.every((v) => typeof v === "number" && Number.isFinite(v))) {
    throw new Error(`${what}: the matrix must be 16 finite numbers (column-major)`);
  }
  return m;
}

export class View3D {
  readonly canvas: HTMLCanvasElement;
  private readonly renderer: WebGLRenderer;
  private readonly scene = new Scene();
  private readonly camera = new PerspectiveCamera(35, 1, 0.1, 10_000);
  private readonly controls: OrbitControls;
  private readonly observer: ResizeObserver;
  private readonly plate = new Group();
  private readonly partsGroup = new Group();
  private readonly entries = new Map<string, Entry>();
  private plateSize = { x: 0, y: 0, z: 0 };
  private selected: string | null = null;
  private slice: Required<View3DSlice> | null = null;
  private selectCb: ((id: string | null) => void) | null = null;
  private dragCb: ((id: string, dx: number, dy: number, done: boolean) => void) | null = null;
  private menuCb: ((id: string | null, x: number, y: number) => void) | null = null;
  /** A right button press under way (a release near it is a right-click: the menu). */
  private rightPress: { pointerId: number; x: number; y: number } | null = null;
  /** When the last right press ended (its contextmenu event may come after it). */
  private rightUp = -Infinity;
  private frame = 0;
  private frames = 0;
  private width = 0;
  private height = 0;
  private press: Press | null = null;
  private disposed = false;

  // clipping: the body keeps z <= top - h, the slab top - h <= z <= top, the cap z <= top
  private readonly clipBody = new Plane(new Vector3(0, 0, -1), NO_CLIP);
  private readonly clipTop = new Plane(new Vector3(0, 0, -1), NO_CLIP);
  private readonly clipSlabBottom = new Plane(new Vector3(0, 0, 1), NO_CLIP);
  /** The overhang tint's uniforms, shared by the body materials (z > 1: no tint). */
  private readonly overhangUniforms = { uOverhangZ: { value: 2 }, uOverhangColor: { value: new Color(COLORS.overhang) } };
  private readonly materials = {
    part: this.bodyMaterial(COLORS.part),
    /** The parts of units 1 … MAX_UNITS − 1 (index u − 1). */
    units: UNIT_COLORS_3D.slice(1).map((c) => this.bodyMaterial(c)),
    selected: this.bodyMaterial(COLORS.selected),
    warn: this.bodyMaterial(COLORS.warn),
    slab: new MeshStandardMaterial({
      color: COLORS.slab,
      roughness: 0.55,
      metalness: 0,
      side: FrontSide,
      clippingPlanes: [this.clipTop, this.clipSlabBottom],
    }),
    cap: new MeshBasicMaterial({ color: COLORS.cap, side: BackSide, clippingPlanes: [this.clipTop] }),
  };

  // scratch objects: nothing is allocated per frame or per pointer move
  private readonly raycaster = new Raycaster();
  private readonly ndc = new Vector2();
  private readonly hits: Intersection[] = [];
  private readonly targets: Object3D[] = [];
  private readonly dragPlane = new Plane();
  private readonly point = new Vector3();
  private readonly moved = new Matrix4();
  private readonly box = new Box3();
  private readonly partBox = new Box3();
  private support: ReturnType<typeof showSupport> = null;

  constructor(private readonly container: HTMLElement) {
    this.renderer = new WebGLRenderer({ antialias: true, preserveDrawingBuffer: true, alpha: false });
    this.renderer.outputColorSpace = SRGBColorSpace;
    this.renderer.localClippingEnabled = true;
    this.renderer.setClearColor(COLORS.background, 1);
    this.canvas = this.renderer.domElement;
    this.canvas.className = "view3d-canvas";
    this.canvas.tabIndex = 0;
    this.canvas.setAttribute("aria-label", "3D view of the plate and the parts");
    container.appendChild(this.canvas);

    this.scene.background = new Color(COLORS.background);
    this.camera.up.set(0, 0, 1);
    this.scene.add(new HemisphereLight(0xffffff, 0x9aa4b0, 1.9));
    this.scene.add(new AmbientLight(0xffffff, 0.25));
    // a light that follows the camera (from above its left shoulder): every side is lit
    const key = new DirectionalLight(0xffffff, 1.6);
    key.position.set(-0.5, 1, 0.6);
    key.target.position.set(0, 0, -1);
    this.camera.add(key, key.target);
    this.scene.add(this.camera, this.plate, this.partsGroup);

    this.controls = new OrbitControls(this.camera, this.canvas);
    this.controls.zoomToCursor = true;
    this.controls.addEventListener("change", this.request);

    // before the controls' own pointerdown (a capture listener on the container runs first)
    container.addEventListener("pointerdown", this.onPointerDown, { capture: true });
    this.canvas.addEventListener("pointermove", this.onPointerMove);
    this.canvas.addEventListener("pointerup", this.onPointerUp);
    this.canvas.addEventListener("pointercancel", this.onPointerCancel);
    this.canvas.addEventListener("contextmenu", this.onContextMenu);
    this.canvas.addEventListener("keydown", this.onKeyDown);

    this.observer = new ResizeObserver(() => this.resize());
    this.observer.observe(container);
    this.resize();
    this.setPlate(154, 134);
    this.fit();
  }

  private bodyMaterial(color: number): MeshStandardMaterial {
    const m = new MeshStandardMaterial({
      color,
      roughness: 0.62,
      metalness: 0,
      side: FrontSide,
      clippingPlanes: [this.clipBody],
    });
    // the overhang tint: the face's normal in plate coordinates (the inverse transpose of the
    // model matrix: right for any scale), compared in the fragment shader
    m.onBeforeCompile = (shader) => {
      shader.uniforms.uOverhangZ = this.overhangUniforms.uOverhangZ;
      shader.uniforms.uOverhangColor = this.overhangUniforms.uOverhangColor;
      shader.vertexShader = shader.vertexShader
        .replace("#include <common>", "#include <common>\nvarying vec3 vPlateNormal;")
        .replace("#include <beginnormal_vertex>", "#include <beginnormal_vertex>\nvPlateNormal = transpose(inverse(mat3(modelMatrix))) * objectNormal;");
      shader.fragmentShader = shader.fragmentShader
        .replace("#include <common>", "#include <common>\nvarying vec3 vPlateNormal;\nuniform float uOverhangZ;\nuniform vec3 uOverhangColor;")
        .replace("#include <color_fragment>", "#include <color_fragment>\nif (normalize(vPlateNormal).z < -uOverhangZ) diffuseColor.rgb = mix(diffuseColor.rgb, uOverhangColor, 0.8);");
    };
    return m;
  }

  /** Tints the faces steeper than `z` allows (see the header); null: no tint. */
  setOverhang(z: number | null): void {
    if (z !== null && !(Number.isFinite(z) && z >= 0 && z <= 1)) throw new Error(`overhang: ${z} must be a number from 0 to 1`);
    const v = z === null ? 2 : z;
    if (this.overhangUniforms.uOverhangZ.value === v) return;
    this.overhangUniforms.uOverhangZ.value = v;
    this.request();
  }

  // ---- plate ----

  setPlate(x: number, y: number, z = 0): void {
    if (!(Number.isFinite(x) && Number.isFinite(y) && x > 0 && y > 0 && x <= PLATE_MAX && y <= PLATE_MAX)) {
      throw new Error(`plate ${x} × ${y} mm: each side must be a number above 0 and at most ${PLATE_MAX} mm`);
    }
    if (!(Number.isFinite(z) && z >= 0 && z <= PLATE_MAX)) throw new Error(`chamber height ${z} mm: it must be a number from 0 to ${PLATE_MAX} mm`);
    if (x === this.plateSize.x && y === this.plateSize.y && z === this.plateSize.z) return;
    this.plateSize = { x, y, z };
    for (const c of [...this.plate.children]) {
      this.plate.remove(c);
      disposeObject(c);
    }
    this.plate.add(...plateObjects(x, y, COLORS, z));
    // a hair below z = 0: the cut's cap shows the inside of a part's bottom, at z = 0 itself
    this.plate.position.z = -0.05;
    this.request();
  }

  // ---- parts ----

  setParts(parts: View3DPart[]): void {
    const seen = new Set<string>();
    for (const p of parts) {
      if (typeof p.id !== "string" || seen.has(p.id)) throw new Error(`part ids must be distinct strings (${JSON.stringify(p.id)} is not)`);
      seen.add(p.id);
      if (!(p.positions instanceof Float32Array) || p.positions.length % 9 !== 0) {
        throw new Error(`part ${p.name || p.id}: positions must be a Float32Array of 9 numbers per triangle`);
      }
      checkMatrix(p.matrix, `part ${p.name || p.id}`);
      if (p.unit !== undefined && !(Number.isInteger(p.unit) && p.unit >= 0 && p.unit < MAX_UNITS)) throw new Error(`part ${p.name || p.id}: unit must be 0 … ${MAX_UNITS - 1}`);
    }
    for (const [id, e] of this.entries) {
      if (!seen.has(id)) this.drop(e);
    }
    for (const p of parts) {
      let e = this.entries.get(p.id);
      if (e && e.positions !== p.positions) {
        this.drop(e);
        e = undefined;
      }
      if (!e) e = this.add(p);
      e.part = p;
      e.unit = p.unit ?? 0;
      e.group.matrix.fromArray(p.matrix);
      e.group.matrixWorldNeedsUpdate = true;
    }
    if (this.selected !== null && !this.entries.has(this.selected)) this.selected = null;
    this.applyMaterials();
    this.request();
  }

  private add(p: View3DPart): Entry {
    const geometry = new BufferGeometry();
    geometry.setAttribute("position", new BufferAttribute(p.positions, 3));
    // non-indexed: each triangle's own normal (flat shading), computed once
    geometry.computeVertexNormals();
    geometry.computeBoundingBox();
    geometry.computeBoundingSphere();
    const group = new Group();
    group.matrixAutoUpdate = false;
    const body = new Mesh(geometry, this.materials.part);
    const slab = new Mesh(geometry, this.materials.slab);
    const cap = new Mesh(geometry, this.materials.cap);
    for (const m of [body, slab, cap]) m.userData.partId = p.id;
    group.add(body, slab, cap);
    this.partsGroup.add(group);
    const e: Entry = { id: p.id, part: p, positions: p.positions, geometry, group, body, slab, cap, unit: p.unit ?? 0 };
    this.entries.set(p.id, e);
    return e;
  }

  private drop(e: Entry): void {
    this.partsGroup.remove(e.group);
    e.geometry.dispose();
    this.entries.delete(e.id);
    if (this.press?.id === e.id) this.endPress(false);
  }

  setMatrix(id: string, matrix: number[]): void {
    const e = this.entries.get(id);
    if (!e) throw new Error(`no part ${JSON.stringify(id)} in the 3D view`);
    checkMatrix(matrix, `part ${e.part.name || id}`);
    e.part.matrix = matrix;
    e.group.matrix.fromArray(matrix);
    e.group.matrixWorldNeedsUpdate = true;
    if (this.press?.id === id) this.press.start.fromArray(matrix);
    this.request();
  }

  select(id: string | null): void {
    const next = id !== null && this.entries.has(id) ? id : null;
    if (next === this.selected) return;
    this.selected = next;
    this.applyMaterials();
    this.request();
  }

  onSelect(cb: (id: string | null) => void): void {
    this.selectCb = cb;
  }

  onDrag(cb: (id: string, dx: number, dy: number, done: boolean) => void): void {
    this.dragCb = cb;
  }

  onMenu(cb: (id: string | null, x: number, y: number) => void): void {
    this.menuCb = cb;
  }

  private applyMaterials(): void {
    for (const e of this.entries.values()) {
      const m = this.materials;
      e.body.material = e.part.warn ? m.warn : e.id === this.selected ? m.selected : e.unit > 0 ? m.units[e.unit - 1] : m.part;
      e.slab.visible = e.cap.visible = this.slice !== null;
    }
  }

  // ---- slice ----

  setSlice(s: View3DSlice | null): void {
    if (s === null) {
      this.slice = null;
      this.clipBody.constant = this.clipTop.constant = this.clipSlabBottom.constant = NO_CLIP;
    } else {
      const { layerHeight: h, layers, current } = s;
      if (!(Number.isFinite(h) && h > 0)) throw new Error(`layer height ${h}: must be a number above 0`);
      if (!(Number.isInteger(layers) && layers > 0)) throw new Error(`layers ${layers}: must be a whole number above 0`);
      if (!(Number.isInteger(current) && current >= 0 && current < layers)) throw new Error(`layer ${current}: must be a whole number in [0, ${layers})`);
      const top = s.top ?? (current + 1) * h;
      if (!Number.isFinite(top)) throw new Error(`layer top ${top}: must be a number`);
      this.slice = { layerHeight: h, layers, current, top };
      // a plane keeps the points p with n·p + constant >= 0
      this.clipBody.constant = top - h; // -z + (top - h) >= 0
      this.clipTop.constant = top; // -z + top >= 0
      this.clipSlabBottom.constant = -(top - h); // z - (top - h) >= 0
    }
    this.applyMaterials();
    this.request();
  }

  setSupport(boxes: Float32Array | null): void {
    this.support = showSupport(this.scene, this.support, boxes, this.clipTop);
    this.request();
  }

  // ---- camera ----

  fit(): void {
    const b = this.box.makeEmpty();
    b.expandByPoint(this.point.set(0, 0, 0)).expandByPoint(this.point.set(this.plateSize.x, this.plateSize.y, 0));
    this.partsGroup.updateMatrixWorld(true);
    for (const e of this.entries.values()) {
      if (e.geometry.boundingBox && !e.geometry.boundingBox.isEmpty()) b.union(this.partBox.copy(e.geometry.boundingBox).applyMatrix4(e.group.matrixWorld));
    }
    const center = b.getCenter(new Vector3());
    center.z *= 0.5;
    // from the front, a little to the left, above: an iso-like view
    const dir = new Vector3(-0.55, -1, 0.85).normalize();
    const right = new Vector3().crossVectors(this.camera.up, dir).normalize();
    const up = new Vector3().crossVectors(dir, right);
    const aspect = this.width > 0 && this.height > 0 ? this.width / this.height : 1.5;
    const tanV = Math.tan((this.camera.fov * Math.PI) / 360);
    const tanH = tanV * aspect;
    // the distance at which every corner of the box is in the picture (with a margin)
    let dist = 1;
    const v = new Vector3();
    for (let i = 0; i < 8; i++) {
      v.set(i & 1 ? b.max.x : b.min.x, i & 2 ? b.max.y : b.min.y, i & 4 ? b.max.z : b.min.z).sub(center);
      const depth = v.dot(dir);
      dist = Math.max(dist, (Math.abs(v.dot(right)) * 1.06) / tanH + depth, (Math.abs(v.dot(up)) * 1.06) / tanV + depth);
    }
    const radius = Math.max(1, b.getSize(v).length() / 2);
    this.camera.position.copy(center).addScaledVector(dir, dist);
    this.camera.near = Math.max(0.01, dist / 200);
    this.camera.far = dist * 20;
    this.camera.updateProjectionMatrix();
    this.controls.target.copy(center);
    this.controls.maxDistance = dist * 8;
    this.controls.minDistance = Math.max(0.5, radius * 0.02);
    this.controls.update();
    this.request();
  }

  pose(): Camera3D {
    const [p, t] = [this.camera.position, this.controls.target];
    return { position: [p.x, p.y, p.z], target: [t.x, t.y, t.z] };
  }

  setPose(c: Camera3D): void {
    const all = [...c.position, ...c.target];
    if (all.length !== 6 || !all.every(Number.isFinite)) throw new Error("a camera is two points of three finite numbers");
    this.camera.position.fromArray(c.position);
    this.controls.target.fromArray(c.target);
    const dist = this.camera.position.distanceTo(this.controls.target);
    [this.camera.near, this.camera.far] = [Math.max(0.01, dist / 200), Math.max(this.camera.far, dist * 20)];
    this.camera.updateProjectionMatrix();
    this.controls.update();
    this.request();
  }

  // ---- drawing ----

  private readonly request = (): void => {
    if (this.frame || this.disposed) return;
    this.frame = requestAnimationFrame(() => {
      this.frame = 0;
      this.renderNow();
    });
  };

  renderNow(): void {
    if (this.disposed || this.width === 0 || this.height === 0) return;
    this.renderer.render(this.scene, this.camera);
    this.frames++;
  }

  private resize(): void {
    const w = this.container.clientWidth;
    const h = this.container.clientHeight;
    if (w === this.width && h === this.height) return;
    this.width = w;
    this.height = h;
    if (w === 0 || h === 0) return;
    this.renderer.setPixelRatio(Math.min(2, window.devicePixelRatio || 1));
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.request();
  }

  state(): { parts: string[]; matrices: Record<string, number[]>; chamber: number; warned: string[]; selected: string | null; slice: View3DSlice | null; overhang: number | null; support: number; frames: number; width: number; height: number } {
    const z = this.overhangUniforms.uOverhangZ.value;
    return {
      parts: [...this.entries.keys()],
      matrices: Object.fromEntries([...this.entries.values()].map((e) => [e.id, e.group.matrix.toArray()])),
      chamber: this.plateSize.z,
      warned: [...this.entries.values()].filter((e) => e.body.material === this.materials.warn).map((e) => e.id),
      selected: this.selected,
      slice: this.slice ? { ...this.slice } : null,
      overhang: z > 1 ? null : z,
      support: this.support?.count ?? 0,
      frames: this.frames,
      width: this.canvas.width,
      height: this.canvas.height,
    };
  }

  // ---- picking and dragging ----

  private ray(ev: MouseEvent): void {
    const r = this.canvas.getBoundingClientRect();
    this.ndc.set(((ev.clientX - r.left) / r.width) * 2 - 1, -((ev.clientY - r.top) / r.height) * 2 + 1);
    this.raycaster.setFromCamera(this.ndc, this.camera);
  }

  /** The visible part under the pointer and where it was hit (in `this.point`); O(triangles). */
  private pick(ev: MouseEvent): string | null {
    this.ray(ev);
    this.scene.updateMatrixWorld();
    this.targets.length = 0;
    for (const e of this.entries.values()) {
      this.targets.push(e.body);
      if (this.slice) this.targets.push(e.slab, e.cap);
    }
    this.hits.length = 0;
    this.raycaster.intersectObjects(this.targets, false, this.hits);
    const top = this.slice ? this.slice.top + 1e-6 : Infinity;
    for (const h of this.hits) {
      // parts above the cut are clipped away: not there to be hit
      if (h.point.z <= top) {
        this.point.copy(h.point);
        return h.object.userData.partId as string;
      }
    }
    return null;
  }

  private readonly onPointerDown = (ev: PointerEvent): void => {
    if (ev.target !== this.canvas) return;
    this.canvas.focus({ preventScroll: true });
    if (this.press) this.endPress(false);
    if (ev.button === 2) this.rightPress = { pointerId: ev.pointerId, x: ev.clientX, y: ev.clientY };
    if (ev.button !== 0 || ev.shiftKey || ev.ctrlKey || ev.metaKey) return;
    // parts are only looked up now when they can be dragged; a click looks them up on release
    const id = this.dragCb ? this.pick(ev) : null;
    const e = id !== null ? this.entries.get(id) : undefined;
    this.press = {
      pointerId: ev.pointerId,
      x: ev.clientX,
      y: ev.clientY,
      id,
      dragging: false,
      origin: this.point.clone(),
      start: e ? e.group.matrix.clone() : new Matrix4(),
      dx: 0,
      dy: 0,
    };
    if (e) {
      // a part grabbed: no orbit (the controls' listener runs after this one)
      this.controls.enabled = false;
      this.canvas.setPointerCapture(ev.pointerId);
      this.dragPlane.setFromNormalAndCoplanarPoint(this.point.set(0, 0, 1), this.press.origin);
    }
  };

  private readonly onPointerMove = (ev: PointerEvent): void => {
    const p = this.press;
    if (!p || ev.pointerId !== p.pointerId || p.id === null || !this.dragCb) return;
    if (!p.dragging && Math.hypot(ev.clientX - p.x, ev.clientY - p.y) < CLICK_PX) return;
    p.dragging = true;
    this.ray(ev);
    if (!this.raycaster.ray.intersectPlane(this.dragPlane, this.point)) return;
    p.dx = this.point.x - p.origin.x;
    p.dy = this.point.y - p.origin.y;
    const e = this.entries.get(p.id);
    if (!e) return;
    this.moved.makeTranslation(p.dx, p.dy, 0);
    e.group.matrix.multiplyMatrices(this.moved, p.start);
    e.group.matrixWorldNeedsUpdate = true;
    this.request();
    this.dragCb(p.id, p.dx, p.dy, false);
  };

  private readonly onPointerUp = (ev: PointerEvent): void => {
    const r = this.rightPress;
    if (ev.button === 2 && r && r.pointerId === ev.pointerId) {
      this.rightPress = null;
      this.rightUp = performance.now();
      if (Math.hypot(ev.clientX - r.x, ev.clientY - r.y) < CLICK_PX && this.menuCb) {
        const id = this.pick(ev);
        if (id !== null) {
          this.select(id);
          this.selectCb?.(this.selected);
          this.menuCb(id, ev.clientX, ev.clientY);
        }
      }
      return;
    }
    const p = this.press;
    if (!p || ev.pointerId !== p.pointerId) return;
    const click = !p.dragging && Math.hypot(ev.clientX - p.x, ev.clientY - p.y) < CLICK_PX;
    this.endPress(true);
    if (click) {
      const id = this.dragCb ? p.id : this.pick(ev);
      this.select(id);
      this.selectCb?.(this.selected);
    }
  };

  private readonly onPointerCancel = (): void => this.endPress(true);

  /** Ends a press; a drag under way is reported as done (`report`). */
  private endPress(report: boolean): void {
    const p = this.press;
    this.press = null;
    this.controls.enabled = true;
    if (p && p.dragging && p.id !== null && report) this.dragCb?.(p.id, p.dx, p.dy, true);
  }

  /** The Menu key or Shift+F10 on the canvas: the selected part's menu (at the canvas' middle). */
  private readonly onKeyDown = (ev: KeyboardEvent): void => {
    if (!this.menuCb || !(ev.key === "ContextMenu" || (ev.key === "F10" && ev.shiftKey))) return;
    ev.preventDefault();
    const r = this.canvas.getBoundingClientRect();
    this.menuCb(null, r.left + r.width / 2, r.top + r.height / 2);
  };

  /** The browser's menu never shows; the ContextMenu key (no right press before it, none just
   *  ended) asks for the selected part's menu. */
  private readonly onContextMenu = (ev: MouseEvent): void => {
    ev.preventDefault();
    if (this.rightPress || performance.now() - this.rightUp < 500 || !this.menuCb) return;
    const r = this.canvas.getBoundingClientRect();
    this.menuCb(null, r.left + r.width / 2, r.top + r.height / 2);
  };

  dispose(): void {
    if (this.disposed) return;
    this.disposed = true;
    if (this.frame) cancelAnimationFrame(this.frame);
    this.observer.disconnect();
    this.controls.removeEventListener("change", this.request);
    this.controls.dispose();
    this.container.removeEventListener("pointerdown", this.onPointerDown, { capture: true });
    this.canvas.removeEventListener("pointermove", this.onPointerMove);
    this.canvas.removeEventListener("pointerup", this.onPointerUp);
    this.canvas.removeEventListener("pointercancel", this.onPointerCancel);
    this.canvas.removeEventListener("contextmenu", this.onContextMenu);
    this.canvas.removeEventListener("keydown", this.onKeyDown);
    for (const e of [...this.entries.values()]) this.drop(e);
    this.support = showSupport(this.scene, this.support, null, this.clipTop);
    disposeObject(this.plate);
    for (const m of Object.values(this.materials).flat()) m.dispose();
    this.renderer.dispose();
    this.canvas.remove();
  }
}
