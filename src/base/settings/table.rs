//! The settings table: every setting once, in display order (docs/spec.md 5.4.1).
//!
//! A row is `scope name: type = default => row(…)`: `job` a setting of the job, `part` one a
//! job file gives per part (its [`super::PART_KEYS`]), `unit` one each discharge unit has —
//! the row is unit 0's (`droplet_aspect`), unit N ≥ 1 has `unitN_droplet_aspect` with the same
//! default and range, described by the text after the row (`{n}`: the unit's number), listed
//! where `@units;` stands. `units` (how many units the machine has, at most [`MAX_UNITS`])
//! bounds `support`, `unit_order` and a part's `unit`. From this table come the
//! [`super::Settings`] struct and its `Default`, the schema ([`super::schema`]), the part
//! keys, the profiles' keys and the page's TypeScript type (`www/core/settings.gen.ts`).
//! `layout(…)` marks what the parts' layout on the plate reads (the page lays the job out
//! again when one of them changes).

use super::schema::*;
use super::{
    ContourOrder, Footprint, LoopSpacing, PrintOrder, SlicePlane, Support, UnitId, UnitOrder,
};

/// The most discharge units a machine may have (`units`, docs/spec.md "Discharge units").
pub const MAX_UNITS: usize = 4;

settings_table! {
    job layer_height: f64 = 0.20 => num("mm", MIN_LAYER_HEIGHT, 5.0, "Droplet", "Layer height H: the height of one droplet");
    unit droplet_aspect: f64 = 1.04 => material(num("", MIN_ASPECT, 10.0, "Droplet", "Droplet width B divided by its height H (B = aspect x H)")), "Droplet width B{n} of discharge unit {n} divided by the layer height";
    job contours: u32 = 2 => int(num("", 0.0, 100.0, "Contours", "Contour loops printed along every boundary (0 = none)"));
    job outer_offset: f64 = 0.5 => num("x B", 0.0, 10.0, "Contours", "Offset of the first loop from an outer boundary, inward, in droplet widths");
    job inner_offset: f64 = 0.5 => num("x B", 0.0, 10.0, "Contours", "Offset of the first loop from a hole boundary, into the material, in droplet widths");
    job start_jitter: f64 = 0.07 => num("mm", 0.0, 1000.0, "Contours", "Each layer's loops start this much further along than the layer below, so loop seams do not stack");
    job stagger: bool = false => flag("Contours", "Set droplets over the gaps of the layer below: every layer's loop droplets half a droplet along from the layer below's (the start moves by start_jitter rounded to an odd multiple of B/2), hatch lines half a spacing across from the last layer with the same hatch direction");
    job contour_order: ContourOrder = ContourOrder::InsideOut => pick(&["inside_out", "outside_in"], "Contours", "inside_out: inner loops before the outermost; outside_in: outermost first");
    job close_loops: bool = true => flag("Contours", "Repeat a loop's first droplet at its end to close it");
    job loop_spacing: LoopSpacing = LoopSpacing::Exact => pick(&["exact", "even"], "Contours", "exact: droplets B apart, the first repeated at the end (the thesis); even: n = ceil(L/B) droplets spaced evenly, no double droplet at the seam");
    job fill_density: f64 = 1.0 => num("", 0.0, 2.0, "Fill", "Hatch spacing = B / fill_density (0 = no fill)");
    job fill_overlap: f64 = 0.5 => num("x B", 0.0, 1.0, "Fill", "How far fill droplets reach into the innermost loop, in droplet widths");
    job hatch_angle: f64 = 45.0 => num("deg", -360.0, 360.0, "Fill", "Hatch direction of the first layer");
    job hatch_angle_step: f64 = 90.0 => num("deg", -360.0, 360.0, "Fill", "Added to the hatch direction from one layer to the next");
    job print_order: PrintOrder = PrintOrder::ContoursFirst => pick(&["contours_first", "fill_first"], "Fill", "contours_first: fill binds to existing loops; fill_first: fill before contours");
    part rotate_x: f64 = 0.0 => num("deg", -360.0, 360.0, "Part", "Rotation of the part about x (applied first)");
    part rotate_y: f64 = 0.0 => num("deg", -360.0, 360.0, "Part", "Rotation of the part about y (applied second)");
    part rotate_z: f64 = 0.0 => num("deg", -360.0, 360.0, "Part", "Rotation of the part about z (applied third)");
    part scale_x: f64 = 1.0 => positive(num("", 0.0, 1000.0, "Part", "Scale factor in x (25.4 turns inches into mm)"));
    part scale_y: f64 = 1.0 => positive(num("", 0.0, 1000.0, "Part", "Scale factor in y"));
    part scale_z: f64 = 1.0 => positive(num("", 0.0, 1000.0, "Part", "Scale factor in z"));
    part place_x: f64 = 0.0 => num("mm", -10000.0, 10000.0, "Part", "Position of the part on the table in x, after its bounding box was moved to the origin");
    part place_y: f64 = 0.0 => num("mm", -10000.0, 10000.0, "Part", "Position of the part on the table in y, after its bounding box was moved to the origin");
    part place_angle: f64 = 0.0 => num("deg", -360.0, 360.0, "Part", "Rotation of the part on the table about z, around the origin, before place_x/place_y");
    job slice_plane: SlicePlane = SlicePlane::Middle => pick(&["middle", "top"], "Part", "Cut each layer at its middle (more accurate) or at its top (the thesis)");
    job units: u32 = 2 => layout(beyond_two(machine(int(num("", 1.0, MAX_UNITS as f64, "Machine", "Discharge units the machine has: unit 0 and units 1 … units - 1 (support, a part's unit and unit_order name only these)")))));
    unit droplet_rate: f64 = 100.0 => machine(num("Hz", MIN_RATE, 100000.0, "Machine", "Droplets the discharge unit sets per second (time estimate)")), "Droplets unit {n} sets per second (time estimate)";
    job travel_speed: f64 = 50.0 => machine(num("mm/s", MIN_RATE, 10000.0, "Machine", "Table speed of travel moves (time estimate)"));
    unit material_density: f64 = 1.04 => material(positive(num("g/cm³", 0.0, 30.0, "Machine", "Density of the material (mass estimate)"))), "Density of unit {n}'s material (mass estimate)";
    unit shrink_xy: f64 = 0.0 => layout(always(material(num("%", 0.0, 5.0, "Machine", "Linear shrinkage of unit 0's material in x and y as it cools: its parts are sliced scaled by 1/(1 - s/100) about their footprint's corner nearest the origin, so the cooled part has the designed size (Mele et al. 2022); support is not scaled")))), "Linear shrinkage of unit {n}'s material in x and y: unit {n}'s parts are sliced scaled by 1/(1 - s/100) (support is not scaled)";
    unit shrink_z: f64 = 0.0 => layout(always(material(num("%", 0.0, 5.0, "Machine", "Linear shrinkage of unit 0's material in z: its parts are sliced scaled by 1/(1 - s/100) in height, still resting on the plate")))), "Linear shrinkage of unit {n}'s material in z: unit {n}'s parts are sliced scaled by 1/(1 - s/100) in height";
    job footprint: Footprint = Footprint::Disc => pick(&["disc", "spread"], "Analysis", "Droplet footprint in the coverage report: disc = diameter B; spread = diameter 2B/sqrt(pi), the area of a B x B cell");
    job plate_x: f64 = 154.0 => layout(machine(num("mm", MIN_PLATE, 100000.0, "Plate", "Build plate size in x: parts without a placement are arranged on it")));
    job plate_y: f64 = 134.0 => layout(machine(num("mm", MIN_PLATE, 100000.0, "Plate", "Build plate size in y")));
    job plate_z: f64 = 230.0 => layout(machine(num("mm", MIN_PLATE, 100000.0, "Plate", "Height of the build chamber: a job taller than this (after scale and shrinkage compensation) is refused before slicing")));
    job part_spacing: f64 = 5.0 => layout(num("mm", 0.0, 1000.0, "Plate", "Gap between the bounding boxes of arranged parts"));
    job allow_off_plate: bool = false => layout(flag("Plate", "Slice a part larger than the plate or reaching past its edges anyway (off: such a job is refused, with the turn or the scale that fits)"));
    job overhang_limit: f64 = 0.5 => num("x B", 0.0, 10.0, "Support", "A droplet is supported when the layer below has material within this many droplet widths of its centre");
    job support: Support = Support::Off => unit_choices(pick(&["off"], "Support", "off: no support; unitN: support under every overhang, printed by discharge unit N (any unit but 0 the machine has, see units)"));
    job support_gap_xy: f64 = 0.5 => second_unit(num("x B", 0.0, 10.0, "Support", "Support is kept this many droplet widths away from the part within a layer"));
    job support_gap_z: u32 = 0 => second_unit(int(num("layers", 0.0, 100.0, "Support", "Support ends this many layers below the overhang (0: a soluble support touches the part)")));
    job support_density: f64 = 1.0 => second_unit(num("", MIN_ASPECT, 1.0, "Support", "Hatch spacing of the support = B1 / support_density"));
    @units;
    job unit_order: UnitOrder = UnitOrder::unit_first(UnitId(0)) => second_unit(order("Units", "Which discharge unit prints first within a layer: unitN_first (then the others by number), or a list of units such as 2,0,1"));
}
