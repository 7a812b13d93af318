//! The plate rule (docs/jobs.md "The plate rule"), one for the command line and the page:
//! every instance must lie on the plate (`plate_x` × `plate_y`) and under the chamber's height
//! (`plate_z`). An instance that does not is a [`Misfit`] with one plain sentence naming the
//! part and what fits instead: the part turned 90° about z, else the largest whole percent of
//! its size. The page shows the sentence with a button per remedy; the command line refuses the
//! job ([`refusal`]) with the sentence and the `--set` or job-file change to make, unless
//! `allow_off_plate` is set.

use crate::base::error::Error;
use crate::base::settings::Settings;
use crate::model::frame::{Frame, Instance, InstanceId};
use serde::{Deserialize, Serialize};

/// Overshoots smaller than this (mm) are rounding, not a part off the plate.
pub const TOLERANCE_MM: f64 = 1e-6;

/// Most misfits a refusal names (the others are counted).
const NAMED: usize = 3;

/// What is wrong with an instance.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify))]
#[serde(rename_all = "snake_case")]
pub enum MisfitKind {
    /// Its footprint is larger than the plate (moving or arranging cannot help).
    Larger,
    /// Taller than the chamber (`plate_z`), its footprint fits the plate.
    Taller,
    /// It would fit, but its place (`place_x`, `place_y`) puts it past an edge of the plate.
    Outside,
}

/// An instance that breaks the plate rule.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
pub struct Misfit {
    /// The instance (`part`, `copy` in the JSON); a part larger than the plate is named once,
    /// for its first copy.
    #[serde(flatten)]
    pub id: InstanceId,
    /// What is wrong: larger than the plate, taller than the chamber, or placed past an edge.
    pub kind: MisfitKind,
    /// One sentence: the part ("Part 1 “name”"), what is wrong, what fits.
    pub message: String,
    /// The part's `rotate_z` with which it fits (turned 90° about z), if it does.
    pub turn_rotate_z: Option<f64>,
    /// The largest whole percent of its size that fits (when the turn does not).
    pub scale_percent: Option<u32>,
    /// The part's `scale_x`, `scale_y`, `scale_z` at `scale_percent`.
    pub scale_to: Option<[f64; 3]>,
}

impl Misfit {
    /// Whether `allow_off_plate` lets the job be sliced anyway (a chamber too low never does).
    pub fn allowed(&self, settings: &Settings) -> bool {
        settings.allow_off_plate && self.kind != MisfitKind::Taller
    }
}

/// How a refusal says what to change: the command line's `--set` (one model) or a job's part
/// keys (`parts[i].key`, a job file or several models).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Hint {
    Set,
    Parts,
}

/// A length as the messages show it: one decimal, no ".0".
fn mm(v: f64) -> String {
    if v < 0.1 {
        return "less than 0.1".into();
    }
    let s = format!("{v:.1}");
    s.strip_suffix(".0").map(str::to_string).unwrap_or(s)
}

/// `deg` + 90, kept within the schema's −360..360.
fn turned(deg: f64) -> f64 {
    let t = deg + 90.0;
    if t > 360.0 { t - 360.0 } else { t }
}

/// The footprint (x, y) of the instance of `frame` and `size` turned 90° about z by its
/// `rotate_z`, when it can be told exactly from the frame (`place_angle` a multiple of 90°).
fn turned_footprint(frame: &Frame, size: [f64; 3], place_angle: f64) -> Option<[f64; 2]> {
    let q = place_angle / 90.0;
    if (q - q.round()).abs() > 1e-9 {
        return None;
    }
    let odd = (q.round() as i64).rem_euclid(2) == 1;
    // The extents before the turn on the plate (place_angle swaps them at odd right angles).
    let [ex, ey] = if odd {
        [size[1], size[0]]
    } else {
        [size[0], size[1]]
    };
    // rotate_z + 90 maps the rotated point u to (−u_y, u_x) before the scale: x' = u_y·sx.
    let (sx, sy) = (frame.scale.x, frame.scale.y);
    let [tx, ty] = [ey / sy * sx, ex / sx * sy];
    Some(if odd { [ty, tx] } else { [tx, ty] })
}

/// The plate rule for one instance: `None` when it lies on the plate and under the chamber.
/// `frame` is its part's, `label` the part's name as the page shows it.
pub fn misfit(inst: &Instance, frame: &Frame, label: &str, s: &Settings) -> Option<Misfit> {
    let (px, py, pz) = (s.plate_x, s.plate_y, s.plate_z);
    let size: [f64; 3] = std::array::from_fn(|k| inst.max[k] - inst.min[k]);
    let wide = size[0] > px + TOLERANCE_MM || size[1] > py + TOLERANCE_MM;
    let tall = size[2] > pz * (1.0 + 1e-12);
    let copy = if inst.copies > 1 {
        format!(" (copy {})", inst.id.copy + 1)
    } else {
        String::new()
    };
    let who = format!("Part {} “{label}”", inst.id.part + 1);
    let mut m = Misfit {
        id: inst.id,
        kind: MisfitKind::Larger,
        message: String::new(),
        turn_rotate_z: None,
        scale_percent: None,
        scale_to: None,
    };
    if !wide && !tall {
        let sides = [
            (-inst.min[0], "left edge"),
            (inst.max[0] - px, "right edge"),
            (-inst.min[1], "front edge"),
            (inst.max[1] - py, "back edge"),
        ];
        let (by, side) =
            sides.into_iter().fold(
                (f64::NEG_INFINITY, ""),
                |a, b| if b.0 > a.0 { b } else { a },
            );
        if by <= TOLERANCE_MM {
            return None;
        }
        m.kind = MisfitKind::Outside;
        m.message = format!(
            "{who}{copy} reaches {} mm past the plate's {side} — move it or press Arrange.",
            mm(by)
        );
        return Some(m);
    }
    if wide && !tall {
        let fits = turned_footprint(frame, size, inst.place_angle)
            .is_some_and(|[x, y]| x <= px + TOLERANCE_MM && y <= py + TOLERANCE_MM);
        if fits {
            m.turn_rotate_z = Some(turned(inst.rotate[2]));
        }
    }
    if m.turn_rotate_z.is_none() {
        let ratio = (px / size[0]).min(py / size[1]).min(pz / size[2]);
        let mut p = (ratio * 100.0).floor();
        // The floor of a product rounded up: one percent less.
        if size
            .iter()
            .zip([px, py, pz])
            .any(|(&a, b)| a * p / 100.0 > b)
        {
            p -= 1.0;
        }
        if (1.0..100.0).contains(&p) {
            m.scale_percent = Some(p as u32);
            m.scale_to = Some(inst.scale.map(|k| k * p / 100.0));
        }
    }
    let what = match (wide, tall) {
        (true, false) => format!(
            "{who} ({} × {} mm) is larger than the plate ({} × {} mm)",
            mm(size[0]),
            mm(size[1]),
            px,
            py
        ),
        (false, _) => {
            m.kind = MisfitKind::Taller;
            format!(
                "{who} is {:.3} mm tall, taller than the build chamber (plate_z {} mm)",
                size[2], pz
            )
        }
        (true, true) => format!(
            "{who} ({} × {} × {} mm) is larger than the plate ({} × {} mm) and taller than the build chamber ({} mm)",
            mm(size[0]),
            mm(size[1]),
            mm(size[2]),
            px,
            py,
            pz
        ),
    };
    let remedy = match (m.turn_rotate_z, m.scale_percent) {
        (Some(_), _) => "turned 90° about z it fits".to_string(),
        (None, Some(p)) => format!("scaled to {p} % it fits"),
        (None, None) => "scale it down to fit".to_string(),
    };
    m.message = format!("{what}; {remedy}.");
    Some(m)
}

/// A number of a suggested setting: at most 4 decimals, no trailing zeros.
fn value(v: f64) -> String {
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

/// The change that makes `m` fit, in the words of `hint`.
fn change(m: &Misfit, hint: Hint) -> String {
    let key = |k: &str| match hint {
        Hint::Set => format!("--set {k}="),
        Hint::Parts => format!("parts[{}].{k} = ", m.id.part),
    };
    let sep = match hint {
        Hint::Set => " ",
        Hint::Parts => ", ",
    };
    let use_ = |keys: Vec<String>| format!(" Use {}", keys.join(sep));
    let mut out = match (m.kind, m.turn_rotate_z, m.scale_to) {
        (MisfitKind::Outside, _, _) => match hint {
            Hint::Set => " Use --set place_x=… --set place_y=… that keep it on the plate".into(),
            Hint::Parts => format!(
                " Change parts[{}].place_x/place_y, or leave them out to have it arranged",
                m.id.part
            ),
        },
        (_, Some(rz), _) => use_(vec![format!("{}{}", key("rotate_z"), value(rz))]),
        (_, None, Some(sc)) => use_(
            ["scale_x", "scale_y", "scale_z"]
                .iter()
                .zip(sc)
                .map(|(k, v)| format!("{}{}", key(k), value(v)))
                .collect(),
        ),
        (_, None, None) => match hint {
            Hint::Set => " Use smaller --set scale_x/scale_y/scale_z".into(),
            Hint::Parts => format!(" Use smaller parts[{}].scale_x/y/z", m.id.part),
        },
    };
    if m.kind != MisfitKind::Taller {
        out.push_str(match hint {
            Hint::Set => ", or --set allow_off_plate=true to slice it as it is.",
            Hint::Parts => ", or the setting allow_off_plate = true to slice it as it is.",
        });
    } else {
        out.push('.');
    }
    out
}

/// The refusal of a job with `misfits` that `settings` do not allow: the misfits' sentences
/// (at most three; the others counted), each with the change that makes it fit, `None` when
/// every misfit is allowed.
pub fn refusal(misfits: &[Misfit], settings: &Settings, hint: Hint) -> Option<Error> {
    let refused: Vec<&Misfit> = misfits.iter().filter(|m| !m.allowed(settings)).collect();
    if refused.is_empty() {
        return None;
    }
    let mut text: Vec<String> = refused
        .iter()
        .take(NAMED)
        .map(|m| format!("{}{}", m.message, change(m, hint)))
        .collect();
    if refused.len() > NAMED {
        text.push(format!(
            "(and {} more off the plate)",
            refused.len() - NAMED
        ));
    }
    let text = text.join(" ");
    Some(if refused.iter().all(|m| m.kind == MisfitKind::Taller) {
        Error::setting("plate_z", text)
    } else {
        Error::Job(text)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::mesh::Placement;

    /// An instance of a box `size` (model coordinates from the origin) with `rotate`, `scale`,
    /// `place_angle` at `place`.
    fn boxed(size: [f64; 3], rotate: [f64; 3], scale: [f64; 3], angle: f64) -> (Instance, Frame) {
        let corners: Vec<[f64; 3]> = (0..8)
            .map(|i| std::array::from_fn(|k| if i >> k & 1 == 1 { size[k] } else { 0.0 }))
            .collect();
        let p = Placement {
            rotate,
            scale,
            place: [0.0, 0.0],
            place_angle: angle,
        };
        let f = Frame::of(&corners, |v| [*v], &p).unwrap();
        let mut inst = Instance {
            copies: 1,
            name: "b".into(),
            file: "b.stl".into(),
            rotate,
            scale,
            place_angle: angle,
            ..Instance::default()
        };
        inst.place(&f, [0.0, 0.0], [-f.qmin.x, -f.qmin.y]);
        (inst, f)
    }

    fn plate(x: f64, y: f64, z: f64) -> Settings {
        Settings {
            plate_x: x,
            plate_y: y,
            plate_z: z,
            ..Settings::default()
        }
    }

    #[test]
    fn a_part_on_the_plate_fits() {
        let (i, f) = boxed([154.0, 134.0, 230.0], [0.0; 3], [1.0; 3], 0.0);
        assert_eq!(misfit(&i, &f, "b.stl", &Settings::default()), None);
    }

    #[test]
    fn the_turn_about_z_is_offered_when_it_fits() {
        // 95.5 × 145 on the 154 × 134 plate: turned, 145 × 95.5 fits.
        let (i, f) = boxed([95.5, 145.0, 60.0], [0.0; 3], [1.0; 3], 0.0);
        let m = misfit(&i, &f, "nefertiti.stl", &Settings::default()).unwrap();
        assert_eq!(m.kind, MisfitKind::Larger);
        assert_eq!(m.turn_rotate_z, Some(90.0));
        assert_eq!(m.scale_percent, None);
        assert_eq!(
            m.message,
            "Part 1 “nefertiti.stl” (95.5 × 145 mm) is larger than the plate (154 × 134 mm); turned 90° about z it fits."
        );
        // The turn really fits: the box turned by the suggested rotate_z.
        let (t, _) = boxed([95.5, 145.0, 60.0], [0.0, 0.0, 90.0], [1.0; 3], 0.0);
        assert!(t.max[0] <= 154.0 && t.max[1] <= 134.0, "{:?}", t.max);
        // From rotate_z 270 the turn is 360; from 300 it wraps to 30 (the schema's range).
        let (i, f) = boxed([145.0, 95.5, 60.0], [0.0, 0.0, 270.0], [1.0; 3], 0.0);
        let m = misfit(&i, &f, "n", &Settings::default()).unwrap();
        assert_eq!(m.turn_rotate_z, Some(360.0));
        assert_eq!(turned(300.0), 30.0);
        assert_eq!(turned(-360.0), -270.0);
    }

    #[test]
    fn the_turn_with_unequal_scales_and_a_place_angle_is_checked_exactly() {
        // 100 × 100 scaled 1.5 × 1 (150 × 100): turned, the scale stays on x, so 150 × 100
        // again — no turn; the scale that fits is offered instead.
        let s = plate(154.0, 134.0, 230.0);
        let (i, f) = boxed([100.0, 100.0, 10.0], [0.0; 3], [1.6, 1.0, 1.0], 0.0);
        let m = misfit(&i, &f, "a", &s).unwrap();
        assert_eq!(m.turn_rotate_z, None);
        assert_eq!(m.scale_percent, Some(96));
        // place_angle 90 swaps the footprint: 130 × 160 does not fit, turned (160 × 130) does.
        let (i, f) = boxed([160.0, 130.0, 10.0], [0.0; 3], [1.0; 3], 90.0);
        assert!(i.max[1] - i.min[1] > 159.0);
        let m = misfit(&i, &f, "a", &plate(170.0, 140.0, 230.0)).unwrap();
        assert_eq!(m.turn_rotate_z, Some(90.0));
        let (t, _) = boxed([160.0, 130.0, 10.0], [0.0, 0.0, 90.0], [1.0; 3], 90.0);
        assert!(t.max[0] - t.min[0] <= 170.0 && t.max[1] - t.min[1] <= 140.0);
        // At 45° the footprint is not told from the frame: no turn offered.
        let (i, f) = boxed([160.0, 10.0, 10.0], [0.0; 3], [1.0; 3], 45.0);
        let m = misfit(&i, &f, "a", &plate(100.0, 100.0, 230.0)).unwrap();
        assert_eq!(m.turn_rotate_z, None);
    }

    #[test]
    fn the_scale_that_fits_is_the_largest_whole_percent() {
        // 200 × 150 on 154 × 134: 154/200 = 0.77, 134/150 = 0.893 → 77 %; turned, 150 × 200
        // does not fit either.
        let (i, f) = boxed([200.0, 150.0, 10.0], [0.0; 3], [1.0, 1.0, 2.0], 0.0);
        let m = misfit(&i, &f, "big.stl", &Settings::default()).unwrap();
        assert_eq!(m.turn_rotate_z, None);
        assert_eq!(m.scale_percent, Some(77));
        assert_eq!(m.scale_to, Some([0.77, 0.77, 1.54]));
        assert!(
            m.message
                .ends_with("is larger than the plate (154 × 134 mm); scaled to 77 % it fits."),
            "{}",
            m.message
        );
        // 77 % fits, 78 % does not.
        for (k, fits) in [(0.77, true), (0.78, false)] {
            let (i, f) = boxed([200.0, 150.0, 10.0], [0.0; 3], [k, k, 2.0 * k], 0.0);
            assert_eq!(
                misfit(&i, &f, "b", &Settings::default()).is_none(),
                fits,
                "{k}"
            );
        }
        // A ratio just under a whole percent: 154/200.5 = 0.7680… → 76 %.
        let (i, f) = boxed([200.5, 150.0, 10.0], [0.0; 3], [1.0; 3], 0.0);
        assert_eq!(
            misfit(&i, &f, "b", &Settings::default())
                .unwrap()
                .scale_percent,
            Some(76)
        );
        // Too tall for the chamber: turning cannot help, the scale counts the height.
        let (i, f) = boxed([50.0, 50.0, 100.0], [0.0; 3], [1.0; 3], 0.0);
        let m = misfit(&i, &f, "t", &plate(154.0, 134.0, 80.0)).unwrap();
        assert_eq!(
            (m.kind, m.scale_percent, m.turn_rotate_z),
            (MisfitKind::Taller, Some(80), None)
        );
        // Wider and taller: the least of the ratios.
        let (i, f) = boxed([308.0, 50.0, 100.0], [0.0; 3], [1.0; 3], 0.0);
        let m = misfit(&i, &f, "t", &plate(154.0, 134.0, 80.0)).unwrap();
        assert_eq!((m.kind, m.scale_percent), (MisfitKind::Larger, Some(50)));
        // Less than 1 % fits: no percent offered, the words say to scale it down.
        let (i, f) = boxed([50_000.0, 50.0, 10.0], [0.0; 3], [1.0; 3], 0.0);
        let m = misfit(&i, &f, "t", &Settings::default()).unwrap();
        assert_eq!(m.scale_percent, None);
        assert!(
            m.message.ends_with("; scale it down to fit."),
            "{}",
            m.message
        );
    }

    #[test]
    fn a_placed_part_past_an_edge_is_told_to_move() {
        let (mut i, f) = boxed([20.0, 20.0, 20.0], [0.0; 3], [1.0; 3], 0.0);
        i.min[0] += 140.0;
        i.max[0] += 140.0;
        let m = misfit(&i, &f, "cube.stl", &Settings::default()).unwrap();
        assert_eq!(m.kind, MisfitKind::Outside);
        assert_eq!(
            m.message,
            "Part 1 “cube.stl” reaches 6 mm past the plate's right edge — move it or press Arrange."
        );
    }

    #[test]
    fn the_refusal_names_the_change_for_the_command_line_and_for_a_job() {
        let (i, f) = boxed([95.5, 145.0, 60.0], [0.0; 3], [1.0; 3], 0.0);
        let s = Settings::default();
        let m = vec![misfit(&i, &f, "n.stl", &s).unwrap()];
        let e = refusal(&m, &s, Hint::Set).unwrap();
        assert_eq!(e.kind(), "job");
        let text = e.to_string();
        assert!(
            text.contains(
                "turned 90° about z it fits. Use --set rotate_z=90, or --set allow_off_plate=true"
            ),
            "{text}"
        );
        let text = refusal(&m, &s, Hint::Parts).unwrap().to_string();
        assert!(
            text.contains("Use parts[0].rotate_z = 90, or the setting allow_off_plate = true"),
            "{text}"
        );
        // Allowed: no refusal; a chamber too low is never allowed.
        let allow = Settings {
            allow_off_plate: true,
            ..s.clone()
        };
        assert_eq!(refusal(&m, &allow, Hint::Set), None);
        let (i, f) = boxed([50.0, 50.0, 100.0], [0.0; 3], [1.0; 3], 0.0);
        let low = Settings {
            plate_z: 80.0,
            ..allow
        };
        let e = refusal(&[misfit(&i, &f, "t", &low).unwrap()], &low, Hint::Set).unwrap();
        assert_eq!(e.report().setting.as_deref(), Some("plate_z"));
        assert!(
            e.to_string()
                .contains("--set scale_x=0.8 --set scale_y=0.8 --set scale_z=0.8."),
            "{e}"
        );
    }
}
