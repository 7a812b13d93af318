//! The settings' schema: every key with its default, unit, range, choices, group and
//! meaning; the page builds its form from it and [`super::Settings::validate`] checks every
//! value against it.

use super::*;

/// The settings that belong to a part, not to a job: the schema flags them
/// ([`SettingSpec::part`]) with their ranges, which a job file's parts are checked against
/// (`crate::model::spec`); the page takes both from the schema.
pub const PART_KEYS: [&str; 9] = [
    "rotate_x",
    "rotate_y",
    "rotate_z",
    "scale_x",
    "scale_y",
    "scale_z",
    "place_x",
    "place_y",
    "place_angle",
];

/// The least layer height, mm (0.1 µm), the least droplet aspect (B/H, and B₁/H; also the
/// least `support_density`), the least droplet rate and travel speed (Hz, mm/s) and the least
/// plate size (mm): with them every derived figure (B², a part's droplets and layers, a
/// print time, a support spacing) stays a finite number a message can show, and a plate of
/// 1e-300 mm is refused for what it is.
pub const MIN_LAYER_HEIGHT: f64 = 1e-4;
pub const MIN_ASPECT: f64 = 1e-3;
pub const MIN_RATE: f64 = 1e-3;
pub const MIN_PLATE: f64 = 1.0;

/// Kind of a setting's value, for the page's form.
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    Number,
    Integer,
    Bool,
    Enum,
}

/// One row of the settings table: name, unit, range, description.
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Debug, Serialize)]
pub struct SettingSpec {
    pub name: &'static str,
    pub kind: Kind,
    pub unit: &'static str,
    /// Smallest allowed value (numbers only).
    pub min: Option<f64>,
    /// Largest allowed value (numbers only).
    pub max: Option<f64>,
    /// `min` itself is not allowed (e.g. a scale must be > 0).
    pub min_exclusive: bool,
    pub choices: &'static [&'static str],
    pub group: &'static str,
    pub description: &'static str,
    /// A key of a part ([`PART_KEYS`]): in a job each part carries its own (docs/jobs.md), and
    /// a job's settings refuse it.
    pub part: bool,
    /// The kind of profile that holds it (docs/process.md), `None`: no profile does.
    pub profile: Option<super::ProfileKind>,
    #[cfg_attr(target_arch = "wasm32", tsify(type = "number | boolean | string"))]
    pub default: serde_json::Value,
}

const NO_CHOICES: &[&str] = &[];

fn num(
    name: &'static str,
    unit: &'static str,
    min: f64,
    max: f64,
    group: &'static str,
    description: &'static str,
) -> SettingSpec {
    SettingSpec {
        name,
        kind: Kind::Number,
        unit,
        min: Some(min),
        max: Some(max),
        min_exclusive: false,
        choices: NO_CHOICES,
        group,
        description,
        part: false,
        profile: None,
        default: serde_json::Value::Null,
    }
}

fn positive(spec: SettingSpec) -> SettingSpec {
    SettingSpec {
        min_exclusive: true,
        ..spec
    }
}

fn choice(
    name: &'static str,
    kind: Kind,
    choices: &'static [&'static str],
    group: &'static str,
    description: &'static str,
) -> SettingSpec {
    SettingSpec {
        name,
        kind,
        unit: "",
        min: None,
        max: None,
        min_exclusive: false,
        choices,
        group,
        description,
        part: false,
        profile: None,
        default: serde_json::Value::Null,
    }
}

/// The settings table in display order, with defaults filled in.
pub fn schema() -> Vec<SettingSpec> {
    let mut specs = vec![
        num(
            "layer_height",
            "mm",
            MIN_LAYER_HEIGHT,
            5.0,
            "Droplet",
            "Layer height H: the height of one droplet",
        ),
        num(
            "droplet_aspect",
            "",
            MIN_ASPECT,
            10.0,
            "Droplet",
            "Droplet width B divided by its height H (B = aspect x H)",
        ),
        SettingSpec {
            kind: Kind::Integer,
            ..num(
                "contours",
                "",
                0.0,
                100.0,
                "Contours",
                "Contour loops printed along every boundary (0 = none)",
            )
        },
        num(
            "outer_offset",
            "x B",
            0.0,
            10.0,
            "Contours",
            "Offset of the first loop from an outer boundary, inward, in droplet widths",
        ),
        num(
            "inner_offset",
            "x B",
            0.0,
            10.0,
            "Contours",
            "Offset of the first loop from a hole boundary, into the material, in droplet widths",
        ),
        num(
            "start_jitter",
            "mm",
            0.0,
            1000.0,
            "Contours",
            "Each layer's loops start this much further along than the layer below, so loop seams do not stack",
        ),
        choice(
            "stagger",
            Kind::Bool,
            NO_CHOICES,
            "Contours",
            "Set droplets over the gaps of the layer below: every layer's loop droplets half a droplet along from the layer below's (the start moves by start_jitter rounded to an odd multiple of B/2), hatch lines half a spacing across from the last layer with the same hatch direction",
        ),
        choice(
            "contour_order",
            Kind::Enum,
            &["inside_out", "outside_in"],
            "Contours",
            "inside_out: inner loops before the outermost; outside_in: outermost first",
        ),
        choice(
            "close_loops",
            Kind::Bool,
            NO_CHOICES,
            "Contours",
            "Repeat a loop's first droplet at its end to close it",
        ),
        choice(
            "loop_spacing",
            Kind::Enum,
            &["exact", "even"],
            "Contours",
            "exact: droplets B apart, the first repeated at the end (the thesis); even: n = ceil(L/B) droplets spaced evenly, no double droplet at the seam",
        ),
        num(
            "fill_density",
            "",
            0.0,
            2.0,
            "Fill",
            "Hatch spacing = B / fill_density (0 = no fill)",
        ),
        num(
            "fill_overlap",
            "x B",
            0.0,
            1.0,
            "Fill",
            "How far fill droplets reach into the innermost loop, in droplet widths",
        ),
        num(
            "hatch_angle",
            "deg",
            -360.0,
            360.0,
            "Fill",
            "Hatch direction of the first layer",
        ),
        num(
            "hatch_angle_step",
            "deg",
            -360.0,
            360.0,
            "Fill",
            "Added to the hatch direction from one layer to the next",
        ),
        choice(
            "print_order",
            Kind::Enum,
            &["contours_first", "fill_first"],
            "Fill",
            "contours_first: fill binds to existing loops; fill_first: fill before contours",
        ),
        num(
            "rotate_x",
            "deg",
            -360.0,
            360.0,
            "Part",
            "Rotation of the part about x (applied first)",
        ),
        num(
            "rotate_y",
            "deg",
            -360.0,
            360.0,
            "Part",
            "Rotation of the part about y (applied second)",
        ),
        num(
            "rotate_z",
            "deg",
            -360.0,
            360.0,
            "Part",
            "Rotation of the part about z (applied third)",
        ),
        positive(num(
            "scale_x",
            "",
            0.0,
            1000.0,
            "Part",
            "Scale factor in x (25.4 turns inches into mm)",
        )),
        positive(num("scale_y", "", 0.0, 1000.0, "Part", "Scale factor in y")),
        positive(num("scale_z", "", 0.0, 1000.0, "Part", "Scale factor in z")),
        num(
            "place_x",
            "mm",
            -10000.0,
            10000.0,
            "Part",
            "Position of the part on the table in x, after its bounding box was moved to the origin",
        ),
        num(
            "place_y",
            "mm",
            -10000.0,
            10000.0,
            "Part",
            "Position of the part on the table in y, after its bounding box was moved to the origin",
        ),
        num(
            "place_angle",
            "deg",
            -360.0,
            360.0,
            "Part",
            "Rotation of the part on the table about z, around the origin, before place_x/place_y",
        ),
        choice(
            "slice_plane",
            Kind::Enum,
            &["middle", "top"],
            "Part",
            "Cut each layer at its middle (more accurate) or at its top (the thesis)",
        ),
        num(
            "droplet_rate",
            "Hz",
            MIN_RATE,
            100000.0,
            "Machine",
            "Droplets the discharge unit sets per second (time estimate)",
        ),
        num(
            "travel_speed",
            "mm/s",
            MIN_RATE,
            10000.0,
            "Machine",
            "Table speed of travel moves (time estimate)",
        ),
        positive(num(
            "material_density",
            "g/cm³",
            0.0,
            30.0,
            "Machine",
            "Density of the material (mass estimate)",
        )),
        num(
            "shrink_xy",
            "%",
            0.0,
            5.0,
            "Machine",
            "Linear shrinkage of unit 0's material in x and y as it cools: its parts are sliced scaled by 1/(1 - s/100) about their footprint's corner nearest the origin, so the cooled part has the designed size (Mele et al. 2022); support is not scaled",
        ),
        num(
            "shrink_z",
            "%",
            0.0,
            5.0,
            "Machine",
            "Linear shrinkage of unit 0's material in z: its parts are sliced scaled by 1/(1 - s/100) in height, still resting on the plate",
        ),
        choice(
            "footprint",
            Kind::Enum,
            &["disc", "spread"],
            "Analysis",
            "Droplet footprint in the coverage report: disc = diameter B; spread = diameter 2B/sqrt(pi), the area of a B x B cell",
        ),
        num(
            "plate_x",
            "mm",
            MIN_PLATE,
            100000.0,
            "Plate",
            "Build plate size in x: parts without a placement are arranged on it",
        ),
        num(
            "plate_y",
            "mm",
            MIN_PLATE,
            100000.0,
            "Plate",
            "Build plate size in y",
        ),
        num(
            "plate_z",
            "mm",
            MIN_PLATE,
            100000.0,
            "Plate",
            "Height of the build chamber: a job taller than this (after scale and shrinkage compensation) is refused before slicing",
        ),
        num(
            "part_spacing",
            "mm",
            0.0,
            1000.0,
            "Plate",
            "Gap between the bounding boxes of arranged parts",
        ),
        choice(
            "allow_off_plate",
            Kind::Bool,
            NO_CHOICES,
            "Plate",
            "Slice a part larger than the plate or reaching past its edges anyway (off: such a job is refused, with the turn or the scale that fits)",
        ),
        num(
            "overhang_limit",
            "x B",
            0.0,
            10.0,
            "Support",
            "A droplet is supported when the layer below has material within this many droplet widths of its centre",
        ),
        choice(
            "support",
            Kind::Enum,
            &["off", "unit1"],
            "Support",
            "off: no support; unit1: support under every overhang, printed by discharge unit 1",
        ),
        num(
            "support_gap_xy",
            "x B",
            0.0,
            10.0,
            "Support",
            "Support is kept this many droplet widths away from the part within a layer",
        ),
        SettingSpec {
            kind: Kind::Integer,
            ..num(
                "support_gap_z",
                "layers",
                0.0,
                100.0,
                "Support",
                "Support ends this many layers below the overhang (0: a soluble support touches the part)",
            )
        },
        num(
            "support_density",
            "",
            MIN_ASPECT,
            1.0,
            "Support",
            "Hatch spacing of the support = B1 / support_density",
        ),
        num(
            "unit1_droplet_aspect",
            "",
            MIN_ASPECT,
            10.0,
            "Unit 1",
            "Droplet width B1 of discharge unit 1 divided by the layer height",
        ),
        num(
            "unit1_droplet_rate",
            "Hz",
            MIN_RATE,
            100000.0,
            "Unit 1",
            "Droplets unit 1 sets per second (time estimate)",
        ),
        positive(num(
            "unit1_material_density",
            "g/cm³",
            0.0,
            30.0,
            "Unit 1",
            "Density of unit 1's material (mass estimate)",
        )),
        num(
            "unit1_shrink_xy",
            "%",
            0.0,
            5.0,
            "Unit 1",
            "Linear shrinkage of unit 1's material in x and y: unit 1's parts are sliced scaled by 1/(1 - s/100) (support is not scaled)",
        ),
        num(
            "unit1_shrink_z",
            "%",
            0.0,
            5.0,
            "Unit 1",
            "Linear shrinkage of unit 1's material in z: unit 1's parts are sliced scaled by 1/(1 - s/100) in height",
        ),
        choice(
            "unit_order",
            Kind::Enum,
            &["unit0_first", "unit1_first"],
            "Unit 1",
            "Which discharge unit prints first within a layer",
        ),
    ];
    let defaults = serde_json::to_value(Settings::default()).expect("settings serialize");
    for spec in &mut specs {
        spec.default = defaults[spec.name].clone();
        spec.part = PART_KEYS.contains(&spec.name);
        spec.profile = [super::ProfileKind::Machine, super::ProfileKind::Material]
            .into_iter()
            .find(|k| k.keys().contains(&spec.name));
    }
    specs
}

/// The schema as JSON, for the page.
pub fn schema_json() -> String {
    serde_json::to_string(&schema()).expect("schema serializes")
}

/// Names of all settings, in schema order.
pub fn names() -> Vec<&'static str> {
    schema().into_iter().map(|s| s.name).collect()
}
