//! The droplet estimate of a whole job, checked when the job is built (before a layer is
//! sliced or a byte written; the page's `Session` builds the same [`crate::Job`]): the parts
//! of unit 0 by their volume and B, the parts of unit 1 by theirs and B₁, and the support by a
//! bound of its region, each against [`MAX_DROPLETS`] in all; the width of unit 1's region in
//! droplets of B₁ against [`MAX_WIDTH_IN_DROPLETS`]; and with support on, the droplets one
//! layer can hold against [`MAX_LAYER_DROPLETS_WITH_SUPPORT`] (the support's droplet-level
//! pass lists a layer's droplets at once) and the whole job against
//! [`MAX_DROPLETS_WITH_SUPPORT`] (the pass checks every droplet). docs/security.md *Droplet budget*.

use crate::base::error::Error;
use crate::base::settings::{Settings, Support};
use crate::model::layout::Instance;
use crate::model::mesh::Mesh;
use crate::model::prepare::{FacetGroup, MAX_WIDTH_IN_DROPLETS};
use crate::pipeline::build::{MAX_DROPLETS, check_droplets};

/// Most droplets one layer may hold with support on: the droplet-level pass
/// ([`crate::support::droplets::complete`]) lists a layer's droplets and sorts them into a grid,
/// about 50 bytes each (0.5 GB per worker at this limit).
pub const MAX_LAYER_DROPLETS_WITH_SUPPORT: f64 = 1e7;

/// Most droplets a job with support on may have (every unit and the support): the support's
/// droplet-level pass checks every droplet of the job against the layer below (about 10 s per
/// 10⁸ droplets natively, more in the page, where each worker runs it).
pub const MAX_DROPLETS_WITH_SUPPORT: f64 = 1e8;

/// The facets unit 1 prints (its parts): their signed volume and bounding box.
#[derive(Clone, Copy, Debug)]
pub struct Unit1Parts {
    signed_volume: f64,
    min: [f64; 3],
    max: [f64; 3],
}

impl Unit1Parts {
    /// The facets of `groups`' unit-1 runs (`None`: no unit-1 facet).
    pub fn of(mesh: &Mesh, groups: &[FacetGroup]) -> Option<Unit1Parts> {
        let mut out = Unit1Parts {
            signed_volume: 0.0,
            min: [f64::INFINITY; 3],
            max: [f64::NEG_INFINITY; 3],
        };
        let mut any = false;
        let mut at = 0usize;
        for g in groups {
            let end = (at + g.facets).min(mesh.facets.len());
            if g.unit == 1 {
                for f in &mesh.facets[at..end] {
                    let [a, b, c] = f.map(|i| mesh.vertices[i as usize]);
                    out.signed_volume += (a[0] * (b[1] * c[2] - b[2] * c[1])
                        - a[1] * (b[0] * c[2] - b[2] * c[0])
                        + a[2] * (b[0] * c[1] - b[1] * c[0]))
                        / 6.0;
                    for p in [a, b, c] {
                        for ((lo, hi), x) in out.min.iter_mut().zip(&mut out.max).zip(p) {
                            *lo = lo.min(x);
                            *hi = hi.max(x);
                        }
                    }
                    any = true;
                }
            }
            at = end;
        }
        any.then_some(out)
    }

    fn size(&self) -> [f64; 3] {
        [0, 1, 2].map(|k| (self.max[k] - self.min[k]).max(0.0))
    }
}

/// The volumes and areas the estimate counts droplets in.
#[derive(Clone, Debug)]
pub struct Estimate {
    /// Unit 0's parts (mm³).
    pub unit0_volume: f64,
    /// Unit 1's parts (mm³).
    pub unit1_volume: f64,
    /// A bound of the support's region (mm³): under each instance's footprint grown by the
    /// support's reach, from the plate to the instance's top.
    pub support_volume: f64,
    /// A bound of the area one layer covers (mm²): the instances' footprints, grown.
    pub footprint: f64,
    /// The width of the region unit 1 prints (mm): its parts', or with support the job's grown.
    pub unit1_extent: f64,
    /// The job's size (mm), for the messages.
    size: [f64; 3],
}

impl Estimate {
    /// The estimate of a job of `size` (mm) whose mesh encloses `volume` (mm³), of which
    /// `unit1` is unit 1's (`open`: some shell is not closed, so unit 1's signed volume means
    /// nothing and its bounding box is taken), placed as `instances` say.
    pub fn new(
        volume: f64,
        unit1: Option<Unit1Parts>,
        open: bool,
        size: &[f64; 3],
        instances: &[Instance],
        s: &Settings,
    ) -> Estimate {
        let (b0, b1) = (s.droplet_width(), s.unit1_droplet_width());
        let (unit0_volume, unit1_volume, unit1_extent) = match unit1 {
            None => (volume, 0.0, 0.0),
            Some(u) => {
                let [x, y, z] = u.size();
                let bbox = x * y * z;
                let v1 = if open {
                    bbox
                } else {
                    u.signed_volume.abs().min(bbox)
                };
                let v0 = if open { volume } else { (volume - v1).max(0.0) };
                (v0, v1, x.max(y))
            }
        };
        let mut e = Estimate {
            unit0_volume,
            unit1_volume,
            support_volume: 0.0,
            footprint: 0.0,
            unit1_extent,
            size: *size,
        };
        // Support lies under overhangs grown by B₁/2 (its droplets on lattice lines B₁ /
        // support_density apart), and the droplet-level pass adds droplets within
        // B₁/2 + overhang_limit × B of a droplet: all within `grow` of the parts' footprints.
        let grow = 2.0 * b1 / s.support_density + s.overhang_limit * b0;
        let grown = |w: f64, d: f64| (w.min(size[0]) + 2.0 * grow) * (d.min(size[1]) + 2.0 * grow);
        let whole = grown(size[0], size[1]);
        let (mut area, mut under) = (0.0, 0.0);
        let bottom = instances
            .iter()
            .map(|i| i.min[2])
            .fold(f64::INFINITY, f64::min);
        for i in instances {
            let a = grown(i.max[0] - i.min[0], i.max[1] - i.min[1]);
            area += a;
            under += a * (i.max[2] - bottom).clamp(0.0, size[2]);
        }
        let ok = |x: f64| x.is_finite() && x > 0.0;
        e.footprint = if instances.len() > 1 && ok(area) {
            area.min(whole)
        } else {
            whole
        };
        e.support_volume = if instances.len() > 1 && ok(under) {
            under.min(whole * size[2])
        } else {
            whole * size[2]
        };
        if s.support == Support::Unit1 {
            e.unit1_extent = size[0].max(size[1]) + 2.0 * grow;
        }
        e
    }

    /// Refuses a job beyond the limits (module doc), naming the unit and the setting to change.
    pub fn check(&self, s: &Settings) -> Result<(), Error> {
        check_droplets(self.unit0_volume, s)?;
        let h = s.layer_height;
        let (b0, b1) = (s.droplet_width(), s.unit1_droplet_width());
        let support = s.support == Support::Unit1;
        let d0 = self.unit0_volume / (b0 * b0 * h);
        let d1 = self.unit1_volume / (b1 * b1 * h);
        let ds = if support {
            s.support_density * self.support_volume / (b1 * b1 * h)
        } else {
            0.0
        };
        let total = d0 + d1 + ds;
        let [x, y, z] = self.size;
        if over(total, MAX_DROPLETS) {
            let (name, message) = if over(d1, ds) && self.unit1_volume > 0.0 {
                (
                    "unit1_droplet_aspect",
                    format!(
                        "the parts of unit 1 ({:.0} mm³) would take about {d1:.1e} droplets of B₁ = {} mm ({total:.1e} for the whole job), more than the {MAX_DROPLETS:.0e} allowed; raise unit1_droplet_aspect (or layer_height)",
                        self.unit1_volume,
                        mm(b1)
                    ),
                )
            } else {
                (
                    "support",
                    format!(
                        "support under the parts ({x:.0} × {y:.0} × {z:.0} mm) could take up to {ds:.1e} droplets of B₁ = {} mm ({total:.1e} for the whole job), more than the {MAX_DROPLETS:.0e} allowed; raise unit1_droplet_aspect (or layer_height), or set support = off",
                        mm(b1)
                    ),
                )
            };
            return Err(Error::Setting {
                name: name.into(),
                message,
            });
        }
        if support && over(total, MAX_DROPLETS_WITH_SUPPORT) {
            let (name, what) = if d0 >= d1.max(ds) {
                (
                    "droplet_aspect",
                    format!("{d0:.1e} of unit 0's B = {} mm", mm(b0)),
                )
            } else if d1 >= ds {
                (
                    "unit1_droplet_aspect",
                    format!("{d1:.1e} of unit 1's parts, B₁ = {} mm", mm(b1)),
                )
            } else {
                (
                    "unit1_droplet_aspect",
                    format!("up to {ds:.1e} of support, B₁ = {} mm", mm(b1)),
                )
            };
            return Err(Error::Setting {
                name: name.into(),
                message: format!(
                    "with support the job could take up to {total:.1e} droplets ({what}), more than the {MAX_DROPLETS_WITH_SUPPORT:.0e} the support's check of every droplet allows; raise {name} (or layer_height), or set support = off"
                ),
            });
        }
        let used = support || self.unit1_volume > 0.0;
        let lines = self.unit1_extent / b1;
        if used && over(lines, MAX_WIDTH_IN_DROPLETS) {
            return Err(Error::Setting {
                name: "unit1_droplet_aspect".into(),
                message: format!(
                    "unit 1's region would be {:.0} mm wide{}, more than {MAX_WIDTH_IN_DROPLETS} droplets of B₁ = {} mm; raise unit1_droplet_aspect{}",
                    self.unit1_extent,
                    if support { " (support)" } else { "" },
                    mm(b1),
                    if support { " or set support = off" } else { "" }
                ),
            });
        }
        if support {
            let a = self.footprint;
            let p0 = a / (b0 * b0);
            let p1 = a * (s.support_density + if self.unit1_volume > 0.0 { 1.0 } else { 0.0 })
                / (b1 * b1);
            let per_layer = p0 + p1;
            if over(per_layer, MAX_LAYER_DROPLETS_WITH_SUPPORT) {
                let (name, what) = if p0 >= p1 {
                    ("droplet_aspect", format!("unit 0's B = {} mm", mm(b0)))
                } else {
                    (
                        "unit1_droplet_aspect",
                        format!("unit 1's B₁ = {} mm", mm(b1)),
                    )
                };
                return Err(Error::Setting {
                    name: name.into(),
                    message: format!(
                        "with support a layer of {a:.0} mm² could hold up to {per_layer:.1e} droplets ({what}), more than the {MAX_LAYER_DROPLETS_WITH_SUPPORT:.0e} the support's check of every droplet allows; raise {name} (or layer_height), or set support = off"
                    ),
                });
            }
        }
        Ok(())
    }
}

/// Whether `x` is beyond `limit` (or not a number).
fn over(x: f64, limit: f64) -> bool {
    x.is_nan() || x > limit
}

/// A droplet width for a message: 4 decimals, or 2 significant digits below a micrometre.
pub fn mm(x: f64) -> String {
    if x >= 1e-3 {
        format!("{x:.4}")
    } else {
        format!("{x:.1e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn setting(r: Result<(), Error>) -> String {
        match r {
            Err(Error::Setting { name, .. }) => name,
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn each_unit_and_the_support_count_with_their_own_droplets() {
        let size = [20.0, 20.0, 20.0];
        let s = Settings::default();
        // The 20 mm cube by unit 0, with and without support: well within every limit.
        let e = Estimate::new(8000.0, None, false, &size, &[], &s);
        assert!(e.check(&s).is_ok());
        let on = Settings {
            support: Support::Unit1,
            ..s.clone()
        };
        assert!(
            Estimate::new(8000.0, None, false, &size, &[], &on)
                .check(&on)
                .is_ok()
        );
        // A tiny B₁ does not matter without unit 1, and is refused for the support with it.
        let tiny = Settings {
            unit1_droplet_aspect: 1e-3,
            ..s.clone()
        };
        assert!(e.check(&tiny).is_ok());
        let tiny_on = Settings {
            support: Support::Unit1,
            ..tiny.clone()
        };
        let e = Estimate::new(8000.0, None, false, &size, &[], &tiny_on);
        assert_eq!(setting(e.check(&tiny_on)), "support");
        // A unit-1 part of the whole cube: its droplets are of B₁.
        let cube = Unit1Parts {
            signed_volume: 8000.0,
            min: [0.0; 3],
            max: size,
        };
        let e = Estimate::new(8000.0, Some(cube), false, &size, &[], &tiny);
        assert_eq!(e.unit0_volume, 0.0);
        assert_eq!(setting(e.check(&tiny)), "unit1_droplet_aspect");
        assert!(e.check(&s).is_ok());
        // A small unit-0 B: fine alone, too many for the support's pass.
        let small = Settings {
            droplet_aspect: 0.1,
            ..s.clone()
        };
        let small_on = Settings {
            support: Support::Unit1,
            ..small.clone()
        };
        assert!(
            Estimate::new(8000.0, None, false, &size, &[], &small)
                .check(&small)
                .is_ok()
        );
        let e = Estimate::new(8000.0, None, false, &size, &[], &small_on);
        assert_eq!(setting(e.check(&small_on)), "droplet_aspect");
    }
}
