// HiDPI 2D canvases: one backing-store pixel per device pixel. The layer canvas (render.ts),
// the vertical cut (cutrender.ts) and the per-layer plot (views/plot.ts) size their canvas
// here and are told here when to size it again (the WebGL view, view3d/view3d.ts, has three.js for
// this).
//
//   sizeCanvas(canvas)          the backing store to the CSS box × devicePixelRatio; returns
//                               { cssW, cssH, dpr } (CSS px, device px per CSS px)
//   watchCanvas(canvas, cb)     cb() when the canvas' box changes size (ResizeObserver) and when
//                               the window moves to a screen with another pixel ratio (or zooms)

/** A canvas' size: its CSS box (at least 1 × 1 px) and the device pixels per CSS pixel. */
export interface CanvasSize {
  cssW: number;
  cssH: number;
  dpr: number;
}

/** Sizes the canvas' backing store to its CSS box times the pixel ratio. The store is set
 *  only when its size changes (setting it clears the canvas): the caller draws after this. */
export function sizeCanvas(canvas: HTMLCanvasElement): CanvasSize {
  const r = canvas.getBoundingClientRect();
  const dpr = window.devicePixelRatio || 1;
  const cssW = Math.max(1, r.width);
  const cssH = Math.max(1, r.height);
  const W = Math.round(cssW * dpr);
  const H = Math.round(cssH * dpr);
  if (canvas.width !== W || canvas.height !== H) {
    canvas.width = W;
    canvas.height = H;
  }
  return { cssW, cssH, dpr };
}

/** Calls `onResize` whenever the canvas needs sizing again: its box changed size, or the
 *  pixel ratio changed (another screen, a browser zoom). */
export function watchCanvas(canvas: HTMLCanvasElement, onResize: () => void): void {
  new ResizeObserver(() => onResize()).observe(canvas);
  watchPixelRatio(onResize);
}

/** A media query of the current ratio fires once when it stops matching; then the new one is
 *  watched. */
function watchPixelRatio(onChange: () => void): void {
  const mq = matchMedia(`(resolution: ${window.devicePixelRatio || 1}dppx)`);
  mq.addEventListener(
    "change",
    () => {
      onChange();
      watchPixelRatio(onChange);
    },
    { once: true },
  );
}
