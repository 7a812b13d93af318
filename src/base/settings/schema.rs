//! The settings' schema: every key with its default, unit, range, choices, group and
//! meaning, built from the one table (`table.rs`, through [`settings_table!`]); the page builds
//! its form from it and [`super::Settings::validate`] checks every value against it.

use super::*;
use std::sync::OnceLock;

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
    /// An order of the units: one of the choices (`unitN_first`) or a list of different units
    /// such as `2,0,1` (the others follow by number).
    Order,
}

/// One row of the settings table: name, unit, range, description.
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Debug, Serialize)]
pub struct SettingSpec {
    pub name: &'static str,
    /// Its kind, unit, range and choices (each unit's choices among them).
    #[serde(flatten)]
    pub domain: Domain,
    pub group: &'static str,
    pub description: &'static str,
    /// A key of a part ([`PART_KEYS`]): in a job each part carries its own (docs/jobs.md), and
    /// a job's settings refuse it.
    pub part: bool,
    /// The kind of profile that holds it (docs/process.md), `None`: no profile does.
    pub profile: Option<super::ProfileKind>,
    /// A setting of the job that the parts' layout on the plate reads
    /// ([`crate::model::layout::layout`]: the arrangement, the misfits, the shrinkage's
    /// scale): a change lays the job out again. (The part keys are each part's own: an edit
    /// of a part lays it out in any case.)
    pub layout: bool,
    #[cfg_attr(target_arch = "wasm32", tsify(type = "number | boolean | string"))]
    pub default: serde_json::Value,
}

/// The values a setting takes: their kind, unit, range and choices.
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Domain {
    pub kind: Kind,
    pub unit: &'static str,
    /// Smallest allowed value (numbers only).
    pub min: Option<f64>,
    /// Largest allowed value (numbers only).
    pub max: Option<f64>,
    /// `min` itself is not allowed (e.g. a scale must be > 0).
    pub min_exclusive: bool,
    pub choices: &'static [&'static str],
}

impl Domain {
    /// A number in `[min, max]`.
    pub const fn number(unit: &'static str, min: f64, max: f64) -> Domain {
        Domain {
            kind: Kind::Number,
            unit,
            min: Some(min),
            max: Some(max),
            min_exclusive: false,
            choices: &[],
        }
    }

    /// A whole number in `[min, max]`.
    pub const fn whole(unit: &'static str, min: f64, max: f64) -> Domain {
        Domain {
            kind: Kind::Integer,
            ..Domain::number(unit, min, max)
        }
    }

    /// Whether `x` is in the range: a finite number from `min` (or above it, when
    /// `min_exclusive`) to `max`; without a range, any number is.
    pub fn admits(&self, x: f64) -> bool {
        let (Some(min), Some(max)) = (self.min, self.max) else {
            return true;
        };
        let below = if self.min_exclusive {
            x <= min
        } else {
            x < min
        };
        x.is_finite() && !below && x <= max
    }

    /// The range in words for a message: "at least 0.1 and at most 5", "greater than 0 and
    /// at most 10" (`None`: no range).
    pub fn range_words(&self) -> Option<String> {
        let (min, max) = (self.min?, self.max?);
        let lower = if self.min_exclusive {
            "greater than"
        } else {
            "at least"
        };
        Some(format!("{lower} {min} and at most {max}"))
    }
}

/// How a row of the table is described: everything but its name, scope and default.
#[derive(Clone, Copy, Debug)]
pub struct Row {
    /// Its values (the units' choices not yet among them: `unit_choices`).
    pub domain: Domain,
    /// The choices go on with one per unit: `unitN` (N ≥ 1) after `off` for `support`,
    /// `unitN_first` for `unit_order`.
    pub unit_choices: bool,
    pub group: &'static str,
    pub description: &'static str,
    pub profile: Option<ProfileKind>,
    pub shown: Shown,
    /// The parts' layout reads it ([`SettingSpec::layout`]).
    pub layout: bool,
}

/// When the G-code's header lists a setting (docs/gcode.md): the settings that only matter
/// with a second or a third unit are listed only when the job uses one, so a one-unit job's
/// header reads as it always did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shown {
    /// Always (a per-unit row: unit 0's always, unit N's when unit N prints).
    Used,
    /// A per-unit row listed for units 0 and 1 always, for unit N ≥ 2 when it prints (the
    /// shrinkage: the headers of two-unit machines always listed both units').
    Always,
    /// When a unit other than 0 prints.
    SecondUnit,
    /// When a unit beyond 0 and 1 prints.
    BeyondTwo,
}

/// A number in `[min, max]`.
pub const fn num(
    unit: &'static str,
    min: f64,
    max: f64,
    group: &'static str,
    description: &'static str,
) -> Row {
    Row {
        domain: Domain::number(unit, min, max),
        unit_choices: false,
        group,
        description,
        profile: None,
        shown: Shown::Used,
        layout: false,
    }
}

/// A whole number (in the range of `row`, a [`num`]).
pub const fn int(mut row: Row) -> Row {
    row.domain.kind = Kind::Integer;
    row
}

/// `min` itself not allowed.
pub const fn positive(mut row: Row) -> Row {
    row.domain.min_exclusive = true;
    row
}

/// true or false.
pub const fn flag(group: &'static str, description: &'static str) -> Row {
    let mut row = num("", 0.0, 0.0, group, description);
    row.domain.kind = Kind::Bool;
    (row.domain.min, row.domain.max) = (None, None);
    row
}

/// One of `choices`.
pub const fn pick(
    choices: &'static [&'static str],
    group: &'static str,
    description: &'static str,
) -> Row {
    let mut row = flag(group, description);
    row.domain.kind = Kind::Enum;
    row.domain.choices = choices;
    row
}

/// An order of units: `unitN_first` (the choices, one per unit) or a list such as `2,0,1`.
pub const fn order(group: &'static str, description: &'static str) -> Row {
    let mut row = unit_choices(pick(&[], group, description));
    row.domain.kind = Kind::Order;
    row
}

pub const fn unit_choices(row: Row) -> Row {
    Row {
        unit_choices: true,
        ..row
    }
}

/// Read by the parts' layout on the plate.
pub const fn layout(row: Row) -> Row {
    Row {
        layout: true,
        ..row
    }
}

/// Held by a machine profile.
pub const fn machine(row: Row) -> Row {
    Row {
        profile: Some(ProfileKind::Machine),
        ..row
    }
}

/// Held by a material profile.
pub const fn material(row: Row) -> Row {
    Row {
        profile: Some(ProfileKind::Material),
        ..row
    }
}

pub const fn always(row: Row) -> Row {
    Row {
        shown: Shown::Always,
        ..row
    }
}

pub const fn second_unit(row: Row) -> Row {
    Row {
        shown: Shown::SecondUnit,
        ..row
    }
}

pub const fn beyond_two(row: Row) -> Row {
    Row {
        shown: Shown::BeyondTwo,
        ..row
    }
}

/// Where a row of the table stands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scope {
    Job,
    Part,
    Unit,
    /// `@units;`: the rows of units 1 … [`MAX_UNITS`] − 1 go here.
    UnitBlock,
}

/// One row of the table as the macro lists it.
pub struct TableRow {
    pub scope: Scope,
    pub name: &'static str,
    pub row: Row,
    /// Unit N's description (`{n}` its number), for per-unit rows.
    pub unit_description: &'static str,
}

/// Where a setting's value lives: a field of the job, or unit N's field `base`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Slot {
    Job,
    Unit(UnitId, &'static str),
}

/// One setting as the schema lists it: its spec, where its value lives, when the header
/// shows it.
pub struct Entry {
    pub spec: SettingSpec,
    pub slot: Slot,
    pub shown: Shown,
}

/// Declares every setting once (the table in `table.rs`): the [`Settings`] struct and
/// [`UnitSettings`], their `Default`, the part keys, and the rows the schema is built from.
macro_rules! settings_table {
    (@go [$($j:tt)*] [$($u:tt)*] [$($p:tt)*] [$($r:tt)*]
        job $name:ident : $ty:ty = $def:expr => $row:expr ; $($rest:tt)*) => {
        settings_table!(@go [$($j)* ($name: $ty = $def)] [$($u)*] [$($p)*]
            [$($r)* (Scope::Job, stringify!($name), $row, "")] $($rest)*);
    };
    (@go [$($j:tt)*] [$($u:tt)*] [$($p:tt)*] [$($r:tt)*]
        part $name:ident : $ty:ty = $def:expr => $row:expr ; $($rest:tt)*) => {
        settings_table!(@go [$($j)* ($name: $ty = $def)] [$($u)*] [$($p)* $name]
            [$($r)* (Scope::Part, stringify!($name), $row, "")] $($rest)*);
    };
    (@go [$($j:tt)*] [$($u:tt)*] [$($p:tt)*] [$($r:tt)*]
        unit $name:ident : $ty:ty = $def:expr => $row:expr, $ndesc:literal ; $($rest:tt)*) => {
        settings_table!(@go [$($j)*] [$($u)* ($name: $ty = $def)] [$($p)*]
            [$($r)* (Scope::Unit, stringify!($name), $row, $ndesc)] $($rest)*);
    };
    (@go [$($j:tt)*] [$($u:tt)*] [$($p:tt)*] [$($r:tt)*] @units ; $($rest:tt)*) => {
        settings_table!(@go [$($j)*] [$($u)*] [$($p)*]
            [$($r)* (Scope::UnitBlock, "", pick(&[], "", ""), "")] $($rest)*);
    };
    (@go [$(($jn:ident : $jt:ty = $jd:expr))*] [$(($un:ident : $ut:ty = $ud:expr))*]
        [$($p:ident)*] [$(($rs:expr, $rn:expr, $rr:expr, $rd:expr))*]) => {
        /// Every parameter of a slice (the table in `table.rs`). `Default` gives the defaults
        /// of docs/spec.md 5.4.1; `per_unit` holds every unit's own settings
        /// ([`MAX_UNITS`] of them, whatever `units` says), read with [`Settings::unit`].
        #[derive(Clone, Debug, PartialEq)]
        pub struct Settings {
            $(pub $jn: $jt,)*
            pub per_unit: Vec<UnitSettings>,
        }

        /// The settings one discharge unit has: unit 0's under their plain names
        /// (`droplet_aspect`), unit N's as `unitN_droplet_aspect`.
        #[derive(Clone, Debug, PartialEq)]
        pub struct UnitSettings {
            $(pub $un: $ut,)*
        }

        impl Default for UnitSettings {
            fn default() -> Self {
                UnitSettings { $($un: $ud,)* }
            }
        }

        impl Default for Settings {
            fn default() -> Self {
                Settings {
                    $($jn: $jd,)*
                    per_unit: vec![UnitSettings::default(); MAX_UNITS],
                }
            }
        }

        /// The settings that belong to a part, not to a job: the schema flags them
        /// ([`SettingSpec::part`]) with their ranges, which a job file's parts are checked
        /// against (`crate::model::spec`); the page takes both from the schema.
        pub const PART_KEYS: &[&str] = &[$(stringify!($p)),*];

        pub(super) fn table() -> Vec<TableRow> {
            vec![$(TableRow { scope: $rs, name: $rn, row: $rr, unit_description: $rd }),*]
        }

        settings_table!(@fields Settings [$($jn)*] job_value job_number_mut put_job);
        settings_table!(@fields UnitSettings [$($un)*] value number_mut put);

        impl Settings {
            /// The number setting `name` itself, for tests that put values no setter takes
            /// (NaN); `None` for a setting that is not a number.
            #[doc(hidden)]
            pub fn number_mut(&mut self, name: &str) -> Option<&mut f64> {
                match entry(name).map(|e| e.slot) {
                    Some(Slot::Unit(u, base)) => self.per_unit[u.index()].number_mut(base),
                    _ => self.job_number_mut(name),
                }
            }
        }
    };
    // A struct's fields by name (`$field`s, the names the table gives them): the value as
    // JSON, the number itself, and a value put from JSON; `None` for a name it has not.
    (@fields $ty:ident [$($field:ident)*] $value:ident $number_mut:ident $put:ident) => {
        impl $ty {
            pub(super) fn $value(&self, name: &str) -> Option<serde_json::Value> {
                match name {
                    $(stringify!($field) => Some(serde_json::to_value(&self.$field).expect("a setting serializes")),)*
                    _ => None,
                }
            }

            fn $number_mut(&mut self, name: &str) -> Option<&mut f64> {
                match name {
                    $(stringify!($field) => NumberMut::number_mut(&mut self.$field),)*
                    _ => None,
                }
            }

            pub(super) fn $put(&mut self, name: &str, v: serde_json::Value) -> Option<Result<(), serde_json::Error>> {
                match name {
                    $(stringify!($field) => Some(serde_json::from_value(v).map(|x| self.$field = x)),)*
                    _ => None,
                }
            }
        }
    };
    ($($rows:tt)*) => { settings_table!(@go [] [] [] [] $($rows)*); };
}
pub(super) use settings_table;

/// A setting's field as a number, if it is one ([`Settings::number_mut`]).
pub trait NumberMut {
    fn number_mut(&mut self) -> Option<&mut f64> {
        None
    }
}

impl NumberMut for f64 {
    fn number_mut(&mut self) -> Option<&mut f64> {
        Some(self)
    }
}

impl NumberMut for u32 {}
impl NumberMut for bool {}
impl NumberMut for ContourOrder {}
impl NumberMut for PrintOrder {}
impl NumberMut for SlicePlane {}
impl NumberMut for Footprint {}
impl NumberMut for LoopSpacing {}
impl NumberMut for Support {}
impl NumberMut for UnitOrder {}

fn leak(s: String) -> &'static str {
    Box::leak(s.into_boxed_str())
}

/// The schema's entries in display order, built once from the table.
pub fn entries() -> &'static [Entry] {
    static ENTRIES: OnceLock<Vec<Entry>> = OnceLock::new();
    ENTRIES.get_or_init(|| {
        let rows = super::table::table();
        let defaults = Settings::default();
        let spec = |name: &'static str, row: &Row, description: &'static str, part: bool| {
            let choices: &'static [&'static str] = if row.unit_choices {
                let mut all: Vec<&'static str> = row.domain.choices.to_vec();
                if row.domain.choices.is_empty() {
                    all.extend((0..MAX_UNITS).map(|n| leak(format!("unit{n}_first"))));
                } else {
                    all.extend((1..MAX_UNITS).map(|n| leak(format!("unit{n}"))));
                }
                Box::leak(all.into_boxed_slice())
            } else {
                row.domain.choices
            };
            SettingSpec {
                name,
                domain: Domain {
                    choices,
                    ..row.domain
                },
                group: row.group,
                description,
                part,
                profile: row.profile,
                layout: row.layout,
                default: serde_json::Value::Null,
            }
        };
        let mut out = Vec::new();
        for r in &rows {
            match r.scope {
                Scope::Job | Scope::Part => out.push(Entry {
                    spec: spec(r.name, &r.row, r.row.description, r.scope == Scope::Part),
                    slot: Slot::Job,
                    shown: r.row.shown,
                }),
                Scope::Unit => out.push(Entry {
                    spec: spec(r.name, &r.row, r.row.description, false),
                    slot: Slot::Unit(UnitId(0), r.name),
                    shown: r.row.shown,
                }),
                Scope::UnitBlock => {
                    for n in 1..MAX_UNITS {
                        for u in rows.iter().filter(|u| u.scope == Scope::Unit) {
                            let mut e = spec(
                                leak(UnitId(n as u8).name(u.name)),
                                &u.row,
                                leak(u.unit_description.replace("{n}", &n.to_string())),
                                false,
                            );
                            e.group = leak(format!("Unit {n}"));
                            out.push(Entry {
                                spec: e,
                                slot: Slot::Unit(UnitId(n as u8), u.name),
                                shown: u.row.shown,
                            });
                        }
                    }
                }
            }
        }
        for e in &mut out {
            e.spec.default = defaults.value_at(e.slot, e.spec.name);
        }
        out
    })
}

/// The settings table in display order, with defaults filled in.
pub fn schema() -> Vec<SettingSpec> {
    entries().iter().map(|e| e.spec.clone()).collect()
}

/// The entry of the setting `name`.
pub fn entry(name: &str) -> Option<&'static Entry> {
    entries().iter().find(|e| e.spec.name == name)
}

/// The schema as JSON, for the page.
pub fn schema_json() -> String {
    serde_json::to_string(&schema()).expect("schema serializes")
}

/// Names of all settings, in schema order.
pub fn names() -> Vec<&'static str> {
    entries().iter().map(|e| e.spec.name).collect()
}
