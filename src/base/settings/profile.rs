//! Profiles (docs/spec.md "Profiles"): a named set of settings of one kind, stored as JSON
//! `{"name": …, "kind": "machine" | "material", "settings": {…}}`.
//!
//! A machine profile holds the plate, the number of units, their rates and the travel speed
//! (the rows of the table marked `machine`); a material profile one material — its droplet
//! aspect, density and shrinkage under unit 0's names (`droplet_aspect`) — and applying it
//! names the unit it goes to ([`Profile::apply_to`]). Material profiles saved before held
//! both units' values (`unit1_droplet_aspect`): they still read, and apply as they did. A key
//! of the other kind, or of neither, is refused: a profile is meant to be swapped for another
//! of its kind without touching the rest of the settings (the layer height, the contours, the
//! support… belong to the job, `--set` or a settings file). Every value is checked by the
//! schema as `--set` checks it.

use super::{Settings, Slot, UnitId, entries, schema};
use crate::base::error::{Error, quote};
use serde::{Deserialize, Serialize};
use std::sync::OnceLock;

/// Largest profile file read (a profile holds at most a few dozen settings).
pub const MAX_PROFILE_BYTES: usize = 64 << 10;
/// Longest profile name, in characters.
pub const MAX_PROFILE_NAME_CHARS: usize = 100;

/// What a profile describes.
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ProfileKind {
    Machine,
    Material,
}

impl ProfileKind {
    /// Every setting a profile of this kind may hold (a material profile: also the `unitN_`
    /// forms profiles saved before held).
    pub fn keys(self) -> &'static [&'static str] {
        static KEYS: [OnceLock<Vec<&'static str>>; 2] = [OnceLock::new(), OnceLock::new()];
        KEYS[self as usize].get_or_init(|| {
            (entries().iter())
                .filter(|e| e.spec.profile == Some(self))
                .map(|e| e.spec.name)
                .collect()
        })
    }

    /// The keys a profile of this kind is written with: a machine profile's all, a material
    /// profile's those of one material (unit 0's names).
    pub fn own_keys(self) -> Vec<&'static str> {
        (entries().iter())
            .filter(|e| e.spec.profile == Some(self))
            .filter(|e| {
                self == ProfileKind::Machine || e.slot == Slot::Unit(UnitId::FIRST, e.spec.name)
            })
            .map(|e| e.spec.name)
            .collect()
    }

    fn word(self) -> &'static str {
        match self {
            ProfileKind::Machine => "machine",
            ProfileKind::Material => "material",
        }
    }
}

/// A checked profile: every key of its kind, every value in the schema's range.
#[cfg_attr(target_arch = "wasm32", derive(tsify::Tsify), tsify(missing_as_null))]
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Profile {
    pub name: String,
    pub kind: ProfileKind,
    #[cfg_attr(
        target_arch = "wasm32",
        tsify(type = "Record<string, number | boolean | string>")
    )]
    pub settings: serde_json::Map<String, serde_json::Value>,
}

/// The profile as written, before the checks.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Raw {
    name: String,
    kind: ProfileKind,
    settings: serde_json::Map<String, serde_json::Value>,
}

fn bad(message: String) -> Error {
    Error::Setting {
        name: String::new(),
        message,
    }
}

/// A profile file's bytes as text, by one rule for the CLI's `--profile` and the page's
/// import: UTF-8 (a byte-order mark EF BB BF dropped), or UTF-16 with its byte-order mark
/// (FF FE little-endian, FE FF big-endian); anything else — Latin-1, Windows-1252, UTF-16
/// without a mark, a binary file — is refused with what was found and what to do, never
/// guessed (a guess garbles a name).
pub fn profile_text(bytes: &[u8]) -> Result<String, Error> {
    if bytes.len() > MAX_PROFILE_BYTES {
        return Err(bad(format!(
            "the profile is {} bytes, more than the {MAX_PROFILE_BYTES} a profile may have",
            bytes.len()
        )));
    }
    let utf16 = |rest: &[u8], unit: fn([u8; 2]) -> u16, which: &str| {
        if !rest.len().is_multiple_of(2) {
            return Err(bad(format!(
                "the profile starts with the byte-order mark of UTF-16 {which} but has an odd number of bytes: save it again as UTF-8"
            )));
        }
        let units = rest.chunks_exact(2).map(|c| unit([c[0], c[1]]));
        char::decode_utf16(units)
            .collect::<Result<String, _>>()
            .map_err(|e| {
                bad(format!(
                    "the profile is not valid UTF-16 {which} (a lone surrogate {:#06x}): save it again as UTF-8",
                    e.unpaired_surrogate()
                ))
            })
    };
    match bytes {
        [0xEF, 0xBB, 0xBF, rest @ ..] => utf8(rest),
        [0xFF, 0xFE, rest @ ..] => utf16(rest, u16::from_le_bytes, "little-endian"),
        [0xFE, 0xFF, rest @ ..] => utf16(rest, u16::from_be_bytes, "big-endian"),
        _ => utf8(bytes),
    }
}

fn utf8(bytes: &[u8]) -> Result<String, Error> {
    String::from_utf8(bytes.to_vec()).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        bad(format!(
            "the profile is not UTF-8 text (byte {:#04x} at offset {at}; Latin-1 or Windows-1252?): save it as UTF-8 (or UTF-16 with a byte-order mark)",
            bytes[at]
        ))
    })
}

/// Characters that show nothing: a name made of them alone (or with spaces) is no name, and
/// they are trimmed from a name's ends with the spaces. The page's `nameProblem`
/// (www/core/profiles.ts) trims the same set.
pub fn invisible(c: char) -> bool {
    matches!(
        c,
        '\u{00AD}'
            | '\u{034F}'
            | '\u{061C}'
            | '\u{180E}'
            | '\u{200B}'..='\u{200F}'
            | '\u{202A}'..='\u{202E}'
            | '\u{2060}'..='\u{2064}'
            | '\u{2066}'..='\u{2069}'
            | '\u{FEFF}'
    )
}

/// A profile's name by the one rule of the CLI and the page: trimmed of spaces and
/// [`invisible`] characters at its ends, 1 to [`MAX_PROFILE_NAME_CHARS`] characters, no
/// control character.
pub fn profile_name(raw: &str) -> Result<&str, Error> {
    let name = raw.trim_matches(|c: char| c.is_whitespace() || invisible(c));
    if name.is_empty() || name.chars().count() > MAX_PROFILE_NAME_CHARS {
        return Err(bad(format!(
            "a profile's name must have 1 to {MAX_PROFILE_NAME_CHARS} visible characters"
        )));
    }
    if name.chars().any(char::is_control) {
        return Err(bad(
            "a profile's name must not hold control characters (line breaks, tabs)".into(),
        ));
    }
    Ok(name)
}

impl Profile {
    /// Reads and checks a profile file's bytes ([`profile_text`], then
    /// [`from_json`](Self::from_json)): what the CLI's `--profile` and the page's import do.
    pub fn from_bytes(bytes: &[u8]) -> Result<Profile, Error> {
        Profile::from_json(&profile_text(bytes)?)
    }

    /// Parses and checks a profile's JSON text (at most [`MAX_PROFILE_BYTES`]).
    pub fn from_json(text: &str) -> Result<Profile, Error> {
        if text.len() > MAX_PROFILE_BYTES {
            return Err(bad(format!(
                "the profile is {} bytes, more than the {MAX_PROFILE_BYTES} a profile may have",
                text.len()
            )));
        }
        let value: serde_json::Value = serde_json::from_str(text)
            .map_err(|e| bad(format!("not JSON: {}", quote(&e.to_string()))))?;
        Profile::from_value(value)
    }

    /// A profile from a parsed JSON value (e.g. from the page), checked.
    pub fn from_value(value: serde_json::Value) -> Result<Profile, Error> {
        let raw: Raw = serde_json::from_value(value).map_err(|e| {
            bad(format!(
                "not a profile ({{\"name\": …, \"kind\": \"machine\" | \"material\", \"settings\": {{…}}}}): {}",
                quote(&e.to_string())
            ))
        })?;
        Profile::checked(raw)
    }

    fn checked(raw: Raw) -> Result<Profile, Error> {
        let name = profile_name(&raw.name)?;
        let kind = raw.kind;
        let known = schema::names();
        for (key, value) in &raw.settings {
            if !kind.keys().contains(&key.as_str()) {
                let other = match kind {
                    ProfileKind::Machine => ProfileKind::Material,
                    ProfileKind::Material => ProfileKind::Machine,
                };
                let why = if other.keys().contains(&key.as_str()) {
                    format!("it belongs in a {} profile", other.word())
                } else if known.contains(&key.as_str()) {
                    "it belongs to the job (give it with --set or a settings file)".into()
                } else {
                    "there is no such setting".into()
                };
                return Err(Error::Setting {
                    name: quote(key),
                    message: format!(
                        "a {} profile holds only {}; {why}",
                        kind.word(),
                        kind.own_keys().join(", ")
                    ),
                });
            }
            let mut s = Settings::default();
            s.set_value(key, value.clone())?;
            s.validate()?;
        }
        Ok(Profile {
            name: name.to_string(),
            kind,
            settings: raw.settings,
        })
    }

    /// Sets the profile's values in `settings` as written (checked when the profile was
    /// made): [`apply_to`](Self::apply_to) without a unit.
    pub fn apply(&self, settings: &mut Settings) -> Result<(), Error> {
        self.apply_to(settings, None)
    }

    /// Sets the profile's values in `settings`. With a unit, a material profile's material
    /// goes to that unit (`droplet_aspect` to `unit2_droplet_aspect` for unit 2); without, each
    /// value goes to the setting its key names (unit 0's, and in a profile saved before with
    /// `unit1_` keys, unit 1's too). A machine profile applies to the machine, never to one
    /// unit; a profile holding several units' values, never to one unit.
    pub fn apply_to(&self, settings: &mut Settings, unit: Option<UnitId>) -> Result<(), Error> {
        let refuse = |why: String| Error::Setting {
            name: String::new(),
            message: format!("the profile {} {why}", quote(&self.name)),
        };
        for (key, value) in &self.settings {
            let name = match unit {
                None => key.clone(),
                Some(_) if self.kind == ProfileKind::Machine => {
                    return Err(refuse(
                        "is a machine profile: it applies to the whole machine, not to one unit (give it without unitN=)".into(),
                    ));
                }
                Some(u) => match super::entry(key).map(|e| e.slot) {
                    Some(Slot::Unit(UnitId::FIRST, base)) => u.name(base),
                    _ => {
                        return Err(refuse(format!(
                            "holds {key}, a setting of one unit: a profile of several units' materials (saved before materials were per unit) applies only as a whole (give it without unitN=)"
                        )));
                    }
                },
            };
            settings.set_value(&name, value.clone())?;
        }
        Ok(())
    }

    /// This profile with its material under unit `u`'s names (`unit2_droplet_aspect` for
    /// `droplet_aspect`), for the command line's `--profile unit2=FILE.json`: refused for a
    /// machine profile and for a profile of several units' materials ([`apply_to`](Self::apply_to)).
    pub fn to_unit(&self, u: UnitId) -> Result<Profile, Error> {
        let mut s = Settings::default();
        self.apply_to(&mut s, Some(u))?;
        let settings = (self.settings.iter())
            .map(|(k, v)| match super::entry(k).map(|e| e.slot) {
                Some(Slot::Unit(_, base)) => (u.name(base), v.clone()),
                _ => (k.clone(), v.clone()),
            })
            .collect();
        Ok(Profile {
            name: self.name.clone(),
            kind: self.kind,
            settings,
        })
    }

    /// How the header names it: `name (kind)`.
    pub fn label(&self) -> String {
        format!("{} ({})", self.name, self.kind.word())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_profile_applies_its_values() {
        let p = material("PC", r#""shrink_xy": 0.8, "material_density": 1.2"#);
        let mut s = Settings::default();
        p.apply(&mut s).unwrap();
        let u0 = s.unit(UnitId::FIRST);
        assert_eq!((u0.shrink_xy, u0.material_density), (0.8, 1.2));
        assert_eq!(p.label(), "PC (material)");
    }

    #[test]
    fn a_material_goes_to_the_unit_named_and_old_profiles_apply_as_before() {
        let pc = material("PC", r#""droplet_aspect": 1.3, "shrink_xy": 0.8"#);
        let mut s = Settings::default();
        pc.apply_to(&mut s, Some(UnitId(2))).unwrap();
        assert_eq!(s.unit(UnitId(2)).droplet_aspect, 1.3);
        assert_eq!(s.unit(UnitId(2)).shrink_xy, 0.8);
        assert_eq!(
            s.unit(UnitId::FIRST),
            Settings::default().unit(UnitId::FIRST)
        );
        assert_eq!(s.unit(UnitId(1)), Settings::default().unit(UnitId(1)));
        let moved = pc.to_unit(UnitId(2)).unwrap();
        assert_eq!(moved.settings["unit2_droplet_aspect"], 1.3);
        assert_eq!(moved.settings.len(), 2);
        // Applying a support material to unit 1 after a PC to unit 0 keeps both.
        let pva = material("PVA", r#""droplet_aspect": 1.6, "material_density": 1.19"#);
        let mut s = Settings::default();
        pc.apply_to(&mut s, Some(UnitId::FIRST)).unwrap();
        pva.apply_to(&mut s, Some(UnitId(1))).unwrap();
        assert_eq!(s.unit(UnitId::FIRST).droplet_aspect, 1.3);
        assert_eq!(s.unit(UnitId(1)).droplet_aspect, 1.6);
        assert_eq!(s.unit(UnitId(1)).material_density, 1.19);
        // A profile saved before, with unit 1's values: read, applied as before, not to one unit.
        let old = material(
            "PC+PVA",
            r#""droplet_aspect": 1.1, "unit1_droplet_aspect": 1.5, "unit1_shrink_z": 0.2"#,
        );
        let mut s = Settings::default();
        old.apply(&mut s).unwrap();
        assert_eq!(s.unit(UnitId::FIRST).droplet_aspect, 1.1);
        assert_eq!(s.unit(UnitId(1)).droplet_aspect, 1.5);
        assert_eq!(s.unit(UnitId(1)).shrink_z, 0.2);
        let e = old
            .apply_to(&mut s, Some(UnitId(2)))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("unit1_droplet_aspect") && e.contains("as a whole"),
            "{e}"
        );
        // A machine profile is the machine's.
        let m = Profile::from_json(&machine("M")).unwrap();
        let e = m.apply_to(&mut s, Some(UnitId(1))).unwrap_err().to_string();
        assert!(e.contains("machine profile"), "{e}");
    }

    #[test]
    fn bad_profiles_are_refused_with_the_key_named() {
        let cases = [
            (
                r#"{"name": "m", "kind": "machine", "settings": {"shrink_xy": 1}}"#,
                "material profile",
            ),
            (
                r#"{"name": "m", "kind": "material", "settings": {"layer_height": 0.2}}"#,
                "belongs to the job",
            ),
            (
                r#"{"name": "m", "kind": "material", "settings": {"colour": 1}}"#,
                "no such setting",
            ),
            (
                r#"{"name": "m", "kind": "material", "settings": {"shrink_z": 9}}"#,
                "out of range",
            ),
            (
                r#"{"name": "m", "kind": "material", "settings": {"shrink_z": "a"}}"#,
                "finite number",
            ),
            (
                r#"{"name": "", "kind": "material", "settings": {}}"#,
                "name",
            ),
            (r#"{"name": "m", "kind": "tool", "settings": {}}"#, "kind"),
            (
                r#"{"name": "m", "kind": "machine", "settings": {}, "x": 1}"#,
                "not a profile",
            ),
            ("[1, 2]", "not a profile"),
        ];
        for (text, expected) in cases {
            let e = Profile::from_json(text).unwrap_err().to_string();
            assert!(e.contains(expected), "{text}: {e}");
        }
        let big = format!(
            r#"{{"name": "{}", "kind": "machine", "settings": {{}}}}"#,
            "a".repeat(MAX_PROFILE_BYTES)
        );
        assert!(
            Profile::from_json(&big)
                .unwrap_err()
                .to_string()
                .contains("bytes")
        );
    }

    /// A material profile `name` with `settings` (the JSON object's members), read.
    fn material(name: &str, settings: &str) -> Profile {
        Profile::from_json(&format!(
            r#"{{"name": "{name}", "kind": "material", "settings": {{{settings}}}}}"#
        ))
        .unwrap()
    }

    fn machine(name: &str) -> String {
        format!(r#"{{"name": "{name}", "kind": "machine", "settings": {{"plate_z": 180}}}}"#)
    }

    fn utf16(text: &str, big_endian: bool) -> Vec<u8> {
        let mut out = if big_endian {
            vec![0xFE, 0xFF]
        } else {
            vec![0xFF, 0xFE]
        };
        for u in text.encode_utf16() {
            out.extend(if big_endian {
                u.to_be_bytes()
            } else {
                u.to_le_bytes()
            });
        }
        out
    }

    #[test]
    fn one_reader_for_every_encoding_with_a_mark() {
        let text = machine("Düsseldorf – 3 µm");
        let plain = text.as_bytes().to_vec();
        let bom = [&[0xEF, 0xBB, 0xBF][..], text.as_bytes()].concat();
        for bytes in [plain, bom, utf16(&text, false), utf16(&text, true)] {
            let p = Profile::from_bytes(&bytes).unwrap();
            assert_eq!(p.name, "Düsseldorf – 3 µm", "{bytes:x?}");
            assert_eq!(p.settings["plate_z"], 180);
        }
    }

    #[test]
    fn latin1_and_unmarked_utf16_are_refused_saying_what_to_do() {
        // "Düsseldorf" in Latin-1: ü is the byte 0xFC.
        let latin1: Vec<u8> = machine("D\u{fc}sseldorf")
            .chars()
            .map(|c| c as u32 as u8)
            .collect();
        let e = Profile::from_bytes(&latin1).unwrap_err().to_string();
        assert!(e.contains("not UTF-8") && e.contains("0xfc"), "{e}");
        assert!(e.contains("save it as UTF-8"), "{e}");
        // UTF-16 without a mark: its zero bytes are valid UTF-8, the JSON is not.
        let unmarked = &utf16(&machine("M"), false)[2..];
        let e = Profile::from_bytes(unmarked).unwrap_err().to_string();
        assert!(e.contains("not JSON"), "{e}");
        // A mark with an odd tail or a lone surrogate.
        let mut odd = utf16(&machine("M"), false);
        odd.push(b' ');
        let e = Profile::from_bytes(&odd).unwrap_err().to_string();
        assert!(e.contains("odd number of bytes"), "{e}");
        let lone = [0xFF, 0xFE, 0x00, 0xD8, b'{', 0];
        let e = Profile::from_bytes(&lone).unwrap_err().to_string();
        assert!(e.contains("surrogate"), "{e}");
        let big = vec![b' '; MAX_PROFILE_BYTES + 1];
        assert!(
            Profile::from_bytes(&big)
                .unwrap_err()
                .to_string()
                .contains("bytes")
        );
    }

    #[test]
    fn a_name_of_invisible_characters_is_no_name() {
        for name in [
            "\u{feff}",
            " \u{200b}\u{feff} ",
            "\u{2060}",
            "\u{00ad}",
            "   ",
        ] {
            let e = Profile::from_json(&machine(name)).unwrap_err().to_string();
            assert!(e.contains("visible characters"), "{name:?}: {e}");
        }
        // Trimmed at the ends, kept inside; the length counted after the trim.
        let p = Profile::from_json(&machine("\u{feff} PLA\u{200b}x ")).unwrap();
        assert_eq!(p.name, "PLA\u{200b}x");
        let long = "a".repeat(MAX_PROFILE_NAME_CHARS);
        assert_eq!(profile_name(&format!("\u{feff}{long} ")).unwrap(), long);
        assert!(profile_name(&format!("{long}b")).is_err());
        assert!(profile_name("a\tb").is_err());
    }
}
