// Droplets as anti-aliased discs written into an RGBA pixel buffer, which the canvas then
// takes in one drawImage. A Canvas path with an `arc` per droplet costs the page's thread (its
// rasterisation, without a GPU) 150–300 ms on a layer of ~25,000 droplets; stamping a
// pre-computed disc into the buffer costs a few ms. Each disc's coverage (the share of a pixel
// inside it, from 8 × 8 samples per pixel) is computed once per radius for 4 × 4 sub-pixel
// positions of the centre, so the picture matches the path's within a sixteenth of a pixel.

/** Sub-pixel positions of a disc's centre per axis (the stamp chosen is the nearest). */
const PHASES = 4;
/** Samples per pixel per axis for a stamp's coverage. */
const SAMPLES = 8;
/** Pixels of stamps painted between two reads of the clock (about 0.3 ms of painting). */
const CHECK_PIXELS = 16384;

/** "#rrggbb" as its three channels. */
export function rgb(hex: string): [number, number, number] {
  const v = parseInt(hex.slice(1), 16);
  return [(v >> 16) & 0xff, (v >> 8) & 0xff, v & 0xff];
}

/** The coverage stamps of a disc of one radius (device px): PHASES² of them, each `size`²
 *  bytes (0–255), the disc's centre at (half + (qx + 0.5) / PHASES, half + (qy + 0.5) /
 *  PHASES) of the stamp. */
export class DiscStamps {
  readonly size: number;
  readonly half: number;
  readonly stamps: Uint8Array[] = [];

  constructor(readonly radius: number) {
    this.half = Math.ceil(radius);
    this.size = 2 * this.half + 2;
    const n = this.size;
    const r2 = radius * radius;
    for (let qy = 0; qy < PHASES; qy++) {
      for (let qx = 0; qx < PHASES; qx++) {
        const cx = this.half + (qx + 0.5) / PHASES;
        const cy = this.half + (qy + 0.5) / PHASES;
        const stamp = new Uint8Array(n * n);
        for (let py = 0; py < n; py++) {
          for (let px = 0; px < n; px++) {
            let inside = 0;
            for (let sy = 0; sy < SAMPLES; sy++) {
              const dy = py + (sy + 0.5) / SAMPLES - cy;
              for (let sx = 0; sx < SAMPLES; sx++) {
                const dx = px + (sx + 0.5) / SAMPLES - cx;
                if (dx * dx + dy * dy <= r2) inside++;
              }
            }
            stamp[py * n + px] = Math.round((inside * 255) / (SAMPLES * SAMPLES));
          }
        }
        this.stamps.push(stamp);
      }
    }
  }
}

/** An RGBA buffer (little-endian pixels, colour not premultiplied) that discs are painted
 *  into, each over what is there (source-over). */
export class DiscBuffer {
  readonly pixels: Uint32Array;
  /** The box painted since the last clear (device px, x0 < x1 and y0 < y1 once anything is). */
  dirty = { x0: 0, y0: 0, x1: 0, y1: 0 };

  constructor(readonly image: ImageData) {
    this.pixels = new Uint32Array(image.data.buffer);
  }

  clear(): void {
    const d = this.dirty;
    const W = this.image.width;
    if (d.x1 > d.x0 && d.y1 > d.y0) {
      for (let y = d.y0; y < d.y1; y++) this.pixels.fill(0, y * W + d.x0, y * W + d.x1);
    }
    this.dirty = { x0: W, y0: this.image.height, x1: 0, y1: 0 };
  }

  /** Marks the whole buffer as painted (its pixels were written directly). */
  touchAll(): void {
    this.dirty = { x0: 0, y0: 0, x1: this.image.width, y1: this.image.height };
  }

  /**
   * Paints a disc of `stamps` in colour `color` at each device position (px) of `at` (x, y
   * pairs; `count` of them) whose `pick` entry is `want` (every one without `pick`); the parts
   * outside the buffer are left out. Starts at disc `from`; past `deadline` (a
   * `performance.now()`) it stops and returns the disc to go on from (`count` when done).
   */
  paint(stamps: DiscStamps, color: [number, number, number], at: Float64Array, count: number, pick: Uint8Array | null, want: number, from = 0, deadline = Infinity): number {
    const W = this.image.width;
    const H = this.image.height;
    const buf = this.pixels;
    const [cr, cg, cb] = color;
    const opaque = (0xff000000 | (cb << 16) | (cg << 8) | cr) >>> 0;
    const rgbOnly = opaque & 0xffffff;
    const n = stamps.size;
    const half = stamps.half;
    // the clock is read every [[CHECK_PIXELS]] pixels of stamps (512 discs of 24 px, as it was,
    // ran 10 ms past a frame's budget)
    const every = Math.max(1, Math.min(512, Math.floor(CHECK_PIXELS / (n * n))));
    let check = from + every;
    for (let k = from; k < count; k++) {
      if (k === check) {
        check += every;
        if (performance.now() > deadline) return k;
      }
      if (pick !== null && pick[k] !== want) continue;
      const x = at[2 * k];
      const y = at[2 * k + 1];
      const fx = Math.floor(x);
      const fy = Math.floor(y);
      const ox = fx - half;
      const oy = fy - half;
      if (!(ox < W && oy < H && ox + n > 0 && oy + n > 0)) continue;
      const qx = Math.min(PHASES - 1, ((x - fx) * PHASES) | 0);
      const qy = Math.min(PHASES - 1, ((y - fy) * PHASES) | 0);
      const stamp = stamps.stamps[qy * PHASES + qx];
      const r0 = Math.max(0, -oy);
      const r1 = Math.min(n, H - oy);
      const c0 = Math.max(0, -ox);
      const c1 = Math.min(n, W - ox);
      const d = this.dirty;
      if (ox + c0 < d.x0) d.x0 = ox + c0;
      if (ox + c1 > d.x1) d.x1 = ox + c1;
      if (oy + r0 < d.y0) d.y0 = oy + r0;
      if (oy + r1 > d.y1) d.y1 = oy + r1;
      for (let r = r0; r < r1; r++) {
        const row = (oy + r) * W + ox;
        const srow = r * n;
        for (let c = c0; c < c1; c++) {
          const a = stamp[srow + c];
          if (a === 0) continue;
          const i = row + c;
          const dst = buf[i];
          const da = dst >>> 24;
          if (a === 255 || da === 0) {
            buf[i] = (rgbOnly | (a << 24)) >>> 0;
            continue;
          }
          if (dst === opaque) continue;
          // source-over, colours not premultiplied: out = a·C + (1 − a)·da·D over out's alpha
          const under = (da * (255 - a)) / 255;
          const oa = a + under;
          const r_ = (cr * a + (dst & 0xff) * under) / oa;
          const g_ = (cg * a + ((dst >>> 8) & 0xff) * under) / oa;
          const b_ = (cb * a + ((dst >>> 16) & 0xff) * under) / oa;
          buf[i] = ((Math.round(oa) << 24) | (Math.round(b_) << 16) | (Math.round(g_) << 8) | Math.round(r_)) >>> 0;
        }
      }
    }
    return count;
  }
}
