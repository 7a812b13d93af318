// Generated from the core's settings table (src/base/settings/table.rs): do not edit.
// `cargo test --release --lib settings` fails when it is stale; with
// DROPSLICE_WRITE_GENERATED=1 it writes it again.

/** The most discharge units a machine may have (the setting `units`). */
export const MAX_UNITS = 4;

/** The settings a part of a job carries itself. */
export const PART_KEYS = ["rotate_x", "rotate_y", "rotate_z", "scale_x", "scale_y", "scale_z", "place_x", "place_y", "place_angle"] as const;
export type PartKey = (typeof PART_KEYS)[number];

/** The settings each unit has (unit 0's names; unit N's are `unitN_` + the name). */
export const UNIT_KEYS = ["droplet_aspect", "droplet_rate", "material_density", "shrink_xy", "shrink_z"] as const;
export type UnitKey = (typeof UNIT_KEYS)[number];

/** Every setting's name, in the table's (the form's) order. */
export const SETTING_NAMES = ["layer_height", "droplet_aspect", "contours", "outer_offset", "inner_offset", "start_jitter", "stagger", "contour_order", "close_loops", "loop_spacing", "fill_density", "fill_overlap", "hatch_angle", "hatch_angle_step", "print_order", "rotate_x", "rotate_y", "rotate_z", "scale_x", "scale_y", "scale_z", "place_x", "place_y", "place_angle", "slice_plane", "units", "droplet_rate", "travel_speed", "material_density", "shrink_xy", "shrink_z", "footprint", "plate_x", "plate_y", "plate_z", "part_spacing", "allow_off_plate", "overhang_limit", "support", "support_gap_xy", "support_gap_z", "support_density", "unit1_droplet_aspect", "unit1_droplet_rate", "unit1_material_density", "unit1_shrink_xy", "unit1_shrink_z", "unit2_droplet_aspect", "unit2_droplet_rate", "unit2_material_density", "unit2_shrink_xy", "unit2_shrink_z", "unit3_droplet_aspect", "unit3_droplet_rate", "unit3_material_density", "unit3_shrink_xy", "unit3_shrink_z", "unit_order"] as const;
export type SettingName = (typeof SETTING_NAMES)[number];

/** Every setting (docs/spec.md 5.4.1). */
export type Settings = {
  /** Layer height H: the height of one droplet (mm) */
  layer_height: number;
  /** Droplet width B divided by its height H (B = aspect x H) */
  droplet_aspect: number;
  /** Contour loops printed along every boundary (0 = none) */
  contours: number;
  /** Offset of the first loop from an outer boundary, inward, in droplet widths (x B) */
  outer_offset: number;
  /** Offset of the first loop from a hole boundary, into the material, in droplet widths (x B) */
  inner_offset: number;
  /** Each layer's loops start this much further along than the layer below, so loop seams do not stack (mm) */
  start_jitter: number;
  /** Set droplets over the gaps of the layer below: every layer's loop droplets half a droplet along from the layer below's (the start moves by start_jitter rounded to an odd multiple of B/2), hatch lines half a spacing across from the last layer with the same hatch direction */
  stagger: boolean;
  /** inside_out: inner loops before the outermost; outside_in: outermost first */
  contour_order: "inside_out" | "outside_in";
  /** Repeat a loop's first droplet at its end to close it */
  close_loops: boolean;
  /** exact: droplets B apart, the first repeated at the end (the thesis); even: n = ceil(L/B) droplets spaced evenly, no double droplet at the seam */
  loop_spacing: "exact" | "even";
  /** Hatch spacing = B / fill_density (0 = no fill) */
  fill_density: number;
  /** How far fill droplets reach into the innermost loop, in droplet widths (x B) */
  fill_overlap: number;
  /** Hatch direction of the first layer (deg) */
  hatch_angle: number;
  /** Added to the hatch direction from one layer to the next (deg) */
  hatch_angle_step: number;
  /** contours_first: fill binds to existing loops; fill_first: fill before contours */
  print_order: "contours_first" | "fill_first";
  /** Rotation of the part about x (applied first) (deg) */
  rotate_x: number;
  /** Rotation of the part about y (applied second) (deg) */
  rotate_y: number;
  /** Rotation of the part about z (applied third) (deg) */
  rotate_z: number;
  /** Scale factor in x (25.4 turns inches into mm) */
  scale_x: number;
  /** Scale factor in y */
  scale_y: number;
  /** Scale factor in z */
  scale_z: number;
  /** Position of the part on the table in x, after its bounding box was moved to the origin (mm) */
  place_x: number;
  /** Position of the part on the table in y, after its bounding box was moved to the origin (mm) */
  place_y: number;
  /** Rotation of the part on the table about z, around the origin, before place_x/place_y (deg) */
  place_angle: number;
  /** Cut each layer at its middle (more accurate) or at its top (the thesis) */
  slice_plane: "middle" | "top";
  /** Discharge units the machine has: unit 0 and units 1 … units - 1 (support, a part's unit and unit_order name only these) */
  units: number;
  /** Droplets the discharge unit sets per second (time estimate) (Hz) */
  droplet_rate: number;
  /** Table speed of travel moves (time estimate) (mm/s) */
  travel_speed: number;
  /** Density of the material (mass estimate) (g/cm³) */
  material_density: number;
  /** Linear shrinkage of unit 0's material in x and y as it cools: its parts are sliced scaled by 1/(1 - s/100) about their footprint's corner nearest the origin, so the cooled part has the designed size (Mele et al. 2022); support is not scaled (%) */
  shrink_xy: number;
  /** Linear shrinkage of unit 0's material in z: its parts are sliced scaled by 1/(1 - s/100) in height, still resting on the plate (%) */
  shrink_z: number;
  /** Droplet footprint in the coverage report: disc = diameter B; spread = diameter 2B/sqrt(pi), the area of a B x B cell */
  footprint: "disc" | "spread";
  /** Build plate size in x: parts without a placement are arranged on it (mm) */
  plate_x: number;
  /** Build plate size in y (mm) */
  plate_y: number;
  /** Height of the build chamber: a job taller than this (after scale and shrinkage compensation) is refused before slicing (mm) */
  plate_z: number;
  /** Gap between the bounding boxes of arranged parts (mm) */
  part_spacing: number;
  /** Slice a part larger than the plate or reaching past its edges anyway (off: such a job is refused, with the turn or the scale that fits) */
  allow_off_plate: boolean;
  /** A droplet is supported when the layer below has material within this many droplet widths of its centre (x B) */
  overhang_limit: number;
  /** off: no support; unitN: support under every overhang, printed by discharge unit N (any unit but 0 the machine has, see units) */
  support: "off" | "unit1" | "unit2" | "unit3";
  /** Support is kept this many droplet widths away from the part within a layer (x B) */
  support_gap_xy: number;
  /** Support ends this many layers below the overhang (0: a soluble support touches the part) (layers) */
  support_gap_z: number;
  /** Hatch spacing of the support = B1 / support_density */
  support_density: number;
  /** Droplet width B1 of discharge unit 1 divided by the layer height */
  unit1_droplet_aspect: number;
  /** Droplets unit 1 sets per second (time estimate) (Hz) */
  unit1_droplet_rate: number;
  /** Density of unit 1's material (mass estimate) (g/cm³) */
  unit1_material_density: number;
  /** Linear shrinkage of unit 1's material in x and y: unit 1's parts are sliced scaled by 1/(1 - s/100) (support is not scaled) (%) */
  unit1_shrink_xy: number;
  /** Linear shrinkage of unit 1's material in z: unit 1's parts are sliced scaled by 1/(1 - s/100) in height (%) */
  unit1_shrink_z: number;
  /** Droplet width B2 of discharge unit 2 divided by the layer height */
  unit2_droplet_aspect: number;
  /** Droplets unit 2 sets per second (time estimate) (Hz) */
  unit2_droplet_rate: number;
  /** Density of unit 2's material (mass estimate) (g/cm³) */
  unit2_material_density: number;
  /** Linear shrinkage of unit 2's material in x and y: unit 2's parts are sliced scaled by 1/(1 - s/100) (support is not scaled) (%) */
  unit2_shrink_xy: number;
  /** Linear shrinkage of unit 2's material in z: unit 2's parts are sliced scaled by 1/(1 - s/100) in height (%) */
  unit2_shrink_z: number;
  /** Droplet width B3 of discharge unit 3 divided by the layer height */
  unit3_droplet_aspect: number;
  /** Droplets unit 3 sets per second (time estimate) (Hz) */
  unit3_droplet_rate: number;
  /** Density of unit 3's material (mass estimate) (g/cm³) */
  unit3_material_density: number;
  /** Linear shrinkage of unit 3's material in x and y: unit 3's parts are sliced scaled by 1/(1 - s/100) (support is not scaled) (%) */
  unit3_shrink_xy: number;
  /** Linear shrinkage of unit 3's material in z: unit 3's parts are sliced scaled by 1/(1 - s/100) in height (%) */
  unit3_shrink_z: number;
  /** Which discharge unit prints first within a layer: unitN_first (then the others by number), or a list of units such as 2,0,1 */
  unit_order: string;
};

/** Every setting's default (the core's `Settings::default()`). */
export const DEFAULTS: Readonly<Settings> = {
  layer_height: 0.2,
  droplet_aspect: 1.04,
  contours: 2,
  outer_offset: 0.5,
  inner_offset: 0.5,
  start_jitter: 0.07,
  stagger: false,
  contour_order: "inside_out",
  close_loops: true,
  loop_spacing: "exact",
  fill_density: 1.0,
  fill_overlap: 0.5,
  hatch_angle: 45.0,
  hatch_angle_step: 90.0,
  print_order: "contours_first",
  rotate_x: 0.0,
  rotate_y: 0.0,
  rotate_z: 0.0,
  scale_x: 1.0,
  scale_y: 1.0,
  scale_z: 1.0,
  place_x: 0.0,
  place_y: 0.0,
  place_angle: 0.0,
  slice_plane: "middle",
  units: 2,
  droplet_rate: 100.0,
  travel_speed: 50.0,
  material_density: 1.04,
  shrink_xy: 0.0,
  shrink_z: 0.0,
  footprint: "disc",
  plate_x: 154.0,
  plate_y: 134.0,
  plate_z: 230.0,
  part_spacing: 5.0,
  allow_off_plate: false,
  overhang_limit: 0.5,
  support: "off",
  support_gap_xy: 0.5,
  support_gap_z: 0,
  support_density: 1.0,
  unit1_droplet_aspect: 1.04,
  unit1_droplet_rate: 100.0,
  unit1_material_density: 1.04,
  unit1_shrink_xy: 0.0,
  unit1_shrink_z: 0.0,
  unit2_droplet_aspect: 1.04,
  unit2_droplet_rate: 100.0,
  unit2_material_density: 1.04,
  unit2_shrink_xy: 0.0,
  unit2_shrink_z: 0.0,
  unit3_droplet_aspect: 1.04,
  unit3_droplet_rate: 100.0,
  unit3_material_density: 1.04,
  unit3_shrink_xy: 0.0,
  unit3_shrink_z: 0.0,
  unit_order: "unit0_first",
};
