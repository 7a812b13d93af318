//! The vertical cut for the page (`www/views/cut.ts`): a [`Session`] method that gives, for a
//! run of layers, the part's section along the line, the droplets near it (for the layers the
//! page does not hold) and the 3D estimate's voids ([`crate::analysis::slab_section_voids`]).
//! Only converts; the model is in `analysis/cut.rs`.

use crate::analysis::{CUT_BANDS, CutLine, Near, footprint_diameter, slab_section_voids};
use crate::base::error::Error;
use crate::base::geom::DVec2;
use crate::output::preview::PreviewLayer;
use crate::wasm::{Session, js_error};
use js_sys::Float64Array;
use wasm_bindgen::prelude::*;

/// `sent[k]` for a layer the page does not hold: the worker plans it.
pub const NOT_SENT: u32 = u32::MAX;

/// Most droplet centres the page may send in one request (x, y pairs).
const MAX_SENT: usize = 1 << 24;

/// The section of a run of layers along a cut line (flat arrays, mm along the line from its
/// first end).
#[wasm_bindgen]
pub struct CutResult {
    droplets: Vec<f64>,
    spans: Vec<f64>,
    voids: Vec<f64>,
}

#[wasm_bindgen]
impl CutResult {
    /// Droplets near the line of the layers the worker planned: layer, t, distance from the
    /// plane, role (0 outer loop, 1 inner loops, 2 fill, 3 support), unit (0 or 1) per droplet.
    #[wasm_bindgen(getter)]
    pub fn droplets(&self) -> Float64Array {
        Float64Array::from(&self.droplets[..])
    }
    /// The part's region along the line: layer, t0, t1 per span.
    #[wasm_bindgen(getter)]
    pub fn spans(&self) -> Float64Array {
        Float64Array::from(&self.spans[..])
    }
    /// The 3D estimate's voids: layer, band (0 … bands − 1 from the slab's bottom), t0, t1.
    #[wasm_bindgen(getter)]
    pub fn voids(&self) -> Float64Array {
        Float64Array::from(&self.voids[..])
    }
    /// Heights sampled per slab ([`CUT_BANDS`]).
    #[wasm_bindgen(getter)]
    pub fn bands(&self) -> usize {
        CUT_BANDS
    }
}

fn bad(message: String) -> JsValue {
    js_error(Error::Internal(format!("cut request: {message}")))
}

#[wasm_bindgen]
impl Session {
    /// The vertical cut along `line` = [ax, ay, bx, by] (mm) for layers [from, to). The voids
    /// of a layer need its neighbours, so the page describes layers [lo, hi) = [from − 1,
    /// to + 1) within the part: `sent[k]` (k = layer − lo) is how many droplet centres it sends
    /// for that layer in `centres` (x, y pairs, one layer after the other: at least every
    /// droplet within B of the line), or [`NOT_SENT`] when it does not hold the layer (the
    /// worker plans it then and returns its droplets near the line).
    pub fn cut(
        &self,
        line: &[f64],
        from: usize,
        to: usize,
        sent: &[u32],
        centres: &[f64],
    ) -> Result<CutResult, JsValue> {
        let n = self.job.layer_count();
        if line.len() != 4 {
            return Err(bad(format!("a line is 4 numbers, not {}", line.len())));
        }
        let line = CutLine::new(DVec2::new(line[0], line[1]), DVec2::new(line[2], line[3]))
            .map_err(js_error)?;
        if !(from < to && to <= n) {
            return Err(bad(format!("layers {from}..{to} of a part of {n}")));
        }
        let (lo, hi) = (from.saturating_sub(1), (to + 1).min(n));
        if sent.len() != hi - lo {
            return Err(bad(format!(
                "{} layer counts for {} layers",
                sent.len(),
                hi - lo
            )));
        }
        let total: usize = sent
            .iter()
            .filter(|&&c| c != NOT_SENT)
            .map(|&c| c as usize)
            .sum();
        if total > MAX_SENT || centres.len() != 2 * total {
            return Err(bad(format!(
                "{} coordinates for {total} droplets (at most {MAX_SENT})",
                centres.len()
            )));
        }
        if !centres.iter().all(|v| v.is_finite()) {
            return Err(bad("a droplet centre is not a number".into()));
        }
        let s = &self.settings;
        let b = s.droplet_width();
        let reach = footprint_diameter(s) / 2.0;
        let mut out = CutResult {
            droplets: Vec::new(),
            spans: Vec::new(),
            voids: Vec::new(),
        };
        // Per layer of [lo, hi): its droplets near the line and (within [from, to)) its region.
        let mut near: Vec<Vec<Near>> = Vec::with_capacity(hi - lo);
        let mut regions = Vec::with_capacity(to - from);
        let mut at = 0;
        for (k, &count) in sent.iter().enumerate() {
            let i = lo + k;
            let wanted = (from..to).contains(&i);
            let layer: Vec<Near> = if count == NOT_SENT {
                let (plan, region) = self.job.plan_layer_and_region(i);
                let p = PreviewLayer::from_plan(&plan, b);
                let points = p
                    .droplets
                    .chunks_exact(2)
                    .map(|c| DVec2::new(c[0] as f64, c[1] as f64));
                let hits = line.near(points, reach);
                if wanted {
                    for &(j, t, d) in &hits {
                        out.droplets.extend([
                            i as f64,
                            t,
                            d,
                            f64::from(p.roles[j]),
                            f64::from(p.units[j]),
                        ]);
                    }
                    regions.push(region);
                }
                hits.into_iter().map(|(_, t, d)| Near { t, d }).collect()
            } else {
                let xy = &centres[at..at + 2 * count as usize];
                at += xy.len();
                if wanted {
                    regions.push(self.job.section(i).region);
                }
                line.near(xy.chunks_exact(2).map(|c| DVec2::new(c[0], c[1])), reach)
                    .into_iter()
                    .map(|(_, t, d)| Near { t, d })
                    .collect()
            };
            near.push(layer);
        }
        for (i, region) in (from..to).zip(&regions) {
            let k = i - lo;
            let spans = line.region_spans(region);
            for &(t0, t1) in &spans {
                out.spans.extend([i as f64, t0, t1]);
            }
            let below = if k > 0 { &near[k - 1][..] } else { &[] };
            let above = near.get(k + 1).map_or(&[][..], |v| &v[..]);
            for v in slab_section_voids(&spans, below, &near[k], above, s) {
                out.voids.extend([i as f64, v.band as f64, v.t0, v.t1]);
            }
        }
        Ok(out)
    }
}
