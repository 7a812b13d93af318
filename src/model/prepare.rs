//! Preparing a model for slicing: the import of one file (bytes → welded, placed mesh), the
//! checks of its size and volume, the repairs (cracks closed, shells oriented, duplicates
//! dropped) and the plain-language warnings about what was found and done.

use crate::base::error::Error;
use crate::base::settings::Settings;
use crate::model::fit;
use crate::model::frame::{Frame, Instance};
use crate::model::import::{self, stl};
use crate::model::mesh::{self, Bounds, Mesh, MeshStats};
use crate::model::shells::{ShellOrientation, Shells};
use crate::model::spec as job;

/// Most layers a job may have (a guard against settings that would run for hours).
pub const MAX_LAYERS: usize = 200_000;
/// Largest part extent in x or y, in droplet widths (hatch lines per layer).
pub const MAX_WIDTH_IN_DROPLETS: f64 = 2_000_000.0;

/// What the import found, for the CLI summary, the header and the page.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
pub struct JobInfo {
    /// The model's file name; for a job, its parts' files (each once, in the parts' order)
    /// joined by ", ", cut after 320 characters with the number of files.
    pub file_name: String,
    /// The model's format; for a job, its first part's.
    pub format: stl::Format,
    /// What welding and checking found in the mesh of every part placed (all copies).
    pub mesh: MeshStats,
    /// Bounding box of the placed part, in mm.
    pub bounds: Bounds,
    /// How many layers the job slices into (each `layer_height` thick), at least 1.
    pub layers: usize,
    /// Droplet width B in mm.
    pub droplet_width: f64,
    /// Problems found in the mesh and what was done about them.
    pub warnings: Vec<String>,
    /// A scale factor for all three axes when the part's size suggests the file is not in
    /// millimetres (25.4: inches; 0.001: micrometres); never applied silently.
    pub suggested_scale: Option<f64>,
    /// Every copy of every part: its file, transform, placement, matrix and bounds.
    #[serde(default)]
    pub instances: Vec<Instance>,
    /// Which discharge unit prints which facets of the prepared mesh: runs of facets in mesh
    /// order, each the instances of consecutive parts of one unit, in the order the parts are
    /// listed (the order that decides who keeps an overlap). Empty: every facet is unit 0's
    /// (every job without unit-1 parts).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub groups: Vec<FacetGroup>,
    /// The profiles applied to the settings, in order (`name (kind)`), for the header.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub profiles: Vec<String>,
}

/// A run of facets of the prepared mesh printed by one discharge unit ([`JobInfo::groups`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
pub struct FacetGroup {
    /// How many facets (they follow the run before).
    pub facets: usize,
    /// The discharge unit, 0 or 1.
    pub unit: u8,
}

/// Drops the facets that were not kept from the runs' counts.
pub(crate) fn keep_groups(groups: &mut [FacetGroup], kept: &[bool]) {
    let mut at = 0;
    for g in groups {
        let end = (at + g.facets).min(kept.len());
        let n = kept[at.min(end)..end].iter().filter(|&&k| k).count();
        at = end;
        g.facets = n;
    }
}

/// Vertices closer than this are merged when exact welding leaves the surface open.
pub const WELD_TOLERANCE_MM: f64 = 1e-4;

/// The unit rule: a part whose largest extent is under 10 mm is probably in inches; one over
/// 2 m probably in micrometres.
pub fn suggested_scale(size: &[f64; 3]) -> Option<f64> {
    let largest = size[0].max(size[1]).max(size[2]);
    if largest < 10.0 {
        Some(25.4)
    } else if largest > 2000.0 {
        Some(0.001)
    } else {
        None
    }
}

/// What [`import`] read.
pub(crate) struct Imported {
    pub(crate) mesh: Mesh,
    pub(crate) format: stl::Format,
    pub(crate) facets_in_file: usize,
    pub(crate) degenerate: usize,
    pub(crate) instance: Instance,
    /// The instance against the plate rule ([`fit::misfit`]).
    pub(crate) misfit: Option<fit::Misfit>,
}

/// What [`Job::build`] needs besides the mesh.
pub(crate) struct Input {
    pub(crate) file_name: String,
    pub(crate) format: stl::Format,
    pub(crate) facets_in_file: usize,
    pub(crate) degenerate: usize,
    pub(crate) instances: Vec<Instance>,
    pub(crate) warnings: Vec<String>,
    /// The instances that break the plate rule: the job is refused for them unless
    /// `allow_off_plate` allows them (then they are warnings).
    pub(crate) misfits: Vec<fit::Misfit>,
    /// How the refusal names the change (the command line's `--set` for one model).
    pub(crate) hint: fit::Hint,
    /// Whose separate bodies the warnings count.
    pub(crate) bodies: Bodies,
    /// [`JobInfo::groups`] of the merged mesh (before the repair drops facets).
    pub(crate) groups: Vec<FacetGroup>,
}

/// Import: STL bytes → triangles → welded mesh → rotated, scaled, placed.
pub(crate) fn import(
    bytes: &[u8],
    file_name: &str,
    settings: &Settings,
) -> Result<Imported, Error> {
    let (tris, format) = import::read_merged(bytes, file_name)?;
    let (mut mesh, degenerate) = Mesh::weld(&tris);
    if mesh.facets.is_empty() {
        return Err(Error::Import(format!(
            "all {} triangles are degenerate (their corners coincide): the mesh has no surface",
            tris.len()
        )));
    }
    let facets_in_file = tris.len();
    drop(tris);
    let placement = mesh::Placement::of_settings(settings)
        .compensated(settings.shrink_factors(crate::base::settings::UnitId::FIRST));
    let frame = Frame::of(&mesh.vertices, |v| [*v], &placement)
        .ok_or_else(|| Error::Internal("a mesh with facets has no vertices".into()))?;
    let place = placement.place;
    let name = job::clean_name(&import::stem(file_name));
    let mut instance = Instance {
        copies: 1,
        name,
        file: job::clean_name(file_name),
        rotate: placement.rotate,
        scale: [settings.scale_x, settings.scale_y, settings.scale_z],
        place_angle: placement.place_angle,
        placed: true,
        size: (frame.max1 - frame.min1).to_array(),
        ..Instance::default()
    };
    instance.place(&frame, place, place);
    mesh.place(&placement);
    let misfit = fit::misfit(&instance, &frame, &job::clean_name(file_name), settings);
    Ok(Imported {
        mesh,
        format,
        facets_in_file,
        degenerate,
        instance,
        misfit,
    })
}

/// Checks: the part has a height, and not too many layers of it.
pub(crate) fn check_height(size: &[f64; 3], settings: &Settings) -> Result<(), Error> {
    let h = settings.layer_height;
    if size[2] <= 0.0 {
        return Err(Error::NothingToPrint(
            "the part is flat (0 mm tall after rotation): check rotate_x/rotate_y".into(),
        ));
    }
    let layers_needed = size[2] / h;
    if layers_needed > MAX_LAYERS as f64 {
        return Err(Error::Setting {
            name: "layer_height".into(),
            message: format!(
                "the part is {:.1} mm tall: {} layers of {} mm are more than the {MAX_LAYERS} allowed; check scale_z and layer_height (is the file in micrometres?)",
                size[2],
                crate::base::error::rounded(layers_needed),
                crate::base::error::number(h)
            ),
        });
    }
    Ok(())
}

/// Checks the job's height against the chamber (`plate_z`), after the other checks of the job
/// (so a job refused for its size or droplets says that first), before anything is sliced.
pub(crate) fn check_chamber(size: &[f64; 3], settings: &Settings) -> Result<(), Error> {
    if size[2] > settings.plate_z * (1.0 + 1e-12) {
        return Err(Error::Setting {
            name: "plate_z".into(),
            message: format!(
                "the job is {:.3} mm tall (after scale and shrinkage compensation), taller than the build chamber (plate_z = {} mm): lay the part down (rotate_x/rotate_y, dropslice orient), scale it down, or set plate_z to the machine's chamber height",
                size[2],
                crate::base::error::number(settings.plate_z)
            ),
        });
    }
    Ok(())
}

/// Checks that the mesh encloses a volume; returns it, mm³ (its droplets are checked when the
/// job is built).
pub(crate) fn check_volume(
    mesh: &Mesh,
    shells: &ShellOrientation,
    size: &[f64; 3],
) -> Result<f64, Error> {
    let volume = mesh.signed_volume().abs().max(shells.closed_volume);
    if size[0] <= 0.0 || size[1] <= 0.0 || volume <= 1e-9 * size[0] * size[1] * size[2] {
        return Err(Error::NothingToPrint(
            "the mesh encloses no volume (a surface without thickness): export the part as a solid"
                .into(),
        ));
    }
    Ok(volume)
}

/// Share of the facets' sides shared with no other facet from which a mesh is refused as a
/// triangle soup ([`check_surface`]).
pub const SOUP_OPEN_SHARE: f64 = 0.5;

/// Refuses a triangle soup: a mesh where at least [`SOUP_OPEN_SHARE`] of the facets' sides
/// (`3 × facets`) are open (`open_edges`: shared with no other facet, after the cracks were
/// closed). Such a file is not the surface of a solid: its sections are loose segments that
/// the slicer would join across the whole part, at a cost growing with the square of the
/// segments crossing a layer (minutes and gigabytes for 50,000 random triangles), into
/// shapes that mean nothing. A mesh with holes, cracks or flipped facets stays far below.
pub(crate) fn check_surface(open_edges: usize, facets: usize) -> Result<(), Error> {
    let sides = 3 * facets;
    if sides == 0 || (open_edges as f64) < SOUP_OPEN_SHARE * sides as f64 {
        return Ok(());
    }
    let share = 100.0 * open_edges as f64 / sides as f64;
    Err(Error::Import(format!(
        "the mesh is not a closed surface: {share:.0} % of its facets' edges ({open_edges} of {sides}) are shared with no other facet, so its {facets} triangles are loose pieces (a triangle soup), not the surface of a solid; repair it in a mesh tool (merge vertices, close holes, make it manifold) and export it as a closed solid"
    )))
}

/// Cracks between near-coincident corners: when the exact weld left open edges, a tolerance
/// weld, kept if it leaves fewer. `shells` are the mesh's ([`Mesh::shells`]). Returns the
/// shells of the mesh as it is then, and how many vertices were merged and facets dropped
/// (both 0: the mesh is unchanged).
pub(crate) fn close_cracks(
    mesh: &mut Mesh,
    shells: Shells,
    groups: &mut [FacetGroup],
) -> (Shells, (usize, usize)) {
    if shells.open_edges == 0 {
        return (shells, (0, 0));
    }
    let mut welded = mesh.clone();
    let (merged, kept) = welded.weld_tolerance_kept(WELD_TOLERANCE_MM);
    if merged == 0 {
        return (shells, (0, 0));
    }
    let better = welded.shells();
    if better.open_edges >= shells.open_edges {
        return (shells, (0, 0));
    }
    let dropped = mesh.facets.len() - welded.facets.len();
    *mesh = welded;
    keep_groups(groups, &kept);
    (better, (merged, dropped))
}

/// Which bodies a job's warning counts: those of its one part's prepared mesh (named), or
/// those counted per part (a job of several instances, whose mesh holds every copy).
pub(crate) enum Bodies {
    Whole(String),
    Parts(Vec<(String, usize)>),
}

/// The warning of a part made of several separate bodies (a file of two cubes), naming it; a
/// job of several parts is not one (docs/jobs.md: every part is its own body).
pub(crate) fn bodies_warning(name: &str, bodies: usize) -> Option<String> {
    (bodies > 1).then(|| {
        format!(
            "Part “{name}” has {bodies} separate bodies; where they overlap they are printed as one"
        )
    })
}

/// The separate bodies of one part's welded mesh, counted as the prepared mesh would count
/// them: when the exact weld left the surface open, after the tolerance weld that closes
/// cracks, if it does ([`close_cracks`]). Cost: one pass over the facets; more only for a part
/// of several bodies with open edges.
pub(crate) fn part_bodies(mesh: &Mesh) -> usize {
    let n = mesh.bodies();
    if n <= 1 {
        return n;
    }
    let shells = mesh.shells();
    if shells.open_edges == 0 {
        return n;
    }
    let mut repaired = mesh.clone();
    let (_, (merged, _)) = close_cracks(&mut repaired, shells, &mut []);
    if merged == 0 { n } else { repaired.bodies() }
}

/// Plain-language warnings about the mesh.
pub(crate) fn warnings(m: &MeshStats, size: &[f64; 3]) -> Vec<String> {
    let counted: [(usize, &str, String); 6] = [
        (m.open_edges, "the mesh is not closed: ", " open edges (holes in the surface); open sections are closed by joining their ends".into()),
        (m.nonmanifold_edges, "", " non-manifold edges (shared by more than two facets); overlapping parts are printed as their union".into()),
        (m.misoriented_edges, "", " edges between facets of opposite orientation (flipped facets); loops are oriented by the majority".into()),
        (m.duplicate_facets, "", " duplicate facets were ignored".into()),
        (m.degenerate_facets, "", " degenerate facets (zero area) were ignored".into()),
        (m.tolerance_welded, "", format!(" near-coincident vertices (closer than {WELD_TOLERANCE_MM} mm) were merged to close cracks in the surface")),
    ];
    let mut w: Vec<String> = counted
        .into_iter()
        .filter(|(n, _, _)| *n > 0)
        .map(|(n, before, after)| format!("{before}{n}{after}"))
        .collect();
    // (count, what, verb for one, verb for several, what was done)
    let shells: [(usize, &str, &str, &str, &str); 4] = [
        (
            m.flipped_shells,
            "closed shell",
            "was",
            "were",
            "inside out (facets facing inward) and outside every other shell: turned outward and printed as solid",
        ),
        (
            m.flipped_open_shells,
            "open shell",
            "was",
            "were",
            "inside out (facets facing inward, holes in the surface) and outside every other shell: turned outward and printed as solid",
        ),
        (
            m.cavity_shells,
            "inside-out closed shell",
            "lies",
            "lie",
            "inside another shell: kept as cavities (hollow inside the part)",
        ),
        (
            m.unchecked_shells,
            "inside-out shell",
            "was",
            "were",
            "not checked (too many to check quickly) and are sliced as they are",
        ),
    ];
    for (n, what, one, several, done) in shells {
        if n > 0 {
            let (s, verb) = if n == 1 { ("", one) } else { ("s", several) };
            w.push(format!("{n} {what}{s} {verb} {done}"));
        }
    }
    if m.signed_volume < 0.0 && m.flipped_shells + m.flipped_open_shells == 0 {
        w.push("the mesh is inside out (its facets face inward); it is sliced as the solid it encloses".into());
    }
    w.extend(scale_warning(size).map(|(text, f)| {
        format!("{text} (--set scale_x={f} --set scale_y={f} --set scale_z={f})")
    }));
    w
}

/// The warning of the unit rule ([`suggested_scale`]) for a part of `size` mm, and the scale
/// it suggests; `None` when the size looks like millimetres.
pub(crate) fn scale_warning(size: &[f64; 3]) -> Option<(String, f64)> {
    let largest = size[0].max(size[1]).max(size[2]);
    let f = suggested_scale(size)?;
    let text = if f > 1.0 {
        format!(
            "the part is only {largest:.3} mm across: if the file is in inches, scale it by {f}"
        )
    } else {
        format!(
            "the part is {largest:.0} mm across: if the file is in micrometres, scale it by {f}"
        )
    };
    Some((text, f))
}
