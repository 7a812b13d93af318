//! The discharge units as values (docs/spec.md "Discharge units"): a unit's number, which unit
//! prints the support, the order the units print in within a layer.

use super::MAX_UNITS;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::fmt;

/// A discharge unit's number, 0 … `units` − 1 (at most [`MAX_UNITS`] − 1).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize,
)]
#[serde(transparent)]
pub struct UnitId(pub u8);

impl UnitId {
    /// The first unit, which prints parts without a unit of their own.
    pub const FIRST: UnitId = UnitId(0);

    pub fn index(self) -> usize {
        usize::from(self.0)
    }

    /// The name of unit N's form of a per-unit setting: `base` for unit 0, `unitN_base`.
    pub fn name(self, base: &str) -> String {
        if self.0 == 0 {
            base.to_string()
        } else {
            format!("unit{}_{base}", self.0)
        }
    }

    /// Every unit a machine of `units` units has.
    pub fn all(units: usize) -> impl Iterator<Item = UnitId> {
        (0..units.min(MAX_UNITS)).map(|n| UnitId(n as u8))
    }

    /// `unitN` as a unit (N within [`MAX_UNITS`]).
    fn parse_word(word: &str) -> Option<UnitId> {
        let n: usize = word.strip_prefix("unit")?.parse().ok()?;
        (n < MAX_UNITS && word == format!("unit{n}")).then_some(UnitId(n as u8))
    }
}

impl fmt::Display for UnitId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0)
    }
}

/// Whether support is printed under overhangs, and by which unit (docs/spec.md "Overhangs
/// and support"): `off`, or `unitN` for any unit but 0.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Support {
    Off,
    /// Support printed by this unit (never unit 0).
    Unit(UnitId),
}

impl Support {
    /// The unit that prints the support, if any.
    pub fn unit(self) -> Option<UnitId> {
        match self {
            Support::Off => None,
            Support::Unit(u) => Some(u),
        }
    }

    pub fn is_on(self) -> bool {
        self != Support::Off
    }
}

impl Serialize for Support {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Support::Off => s.serialize_str("off"),
            Support::Unit(u) => s.serialize_str(&format!("unit{}", u.0)),
        }
    }
}

impl<'de> Deserialize<'de> for Support {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let word = String::deserialize(d)?;
        match UnitId::parse_word(&word) {
            _ if word == "off" => Ok(Support::Off),
            Some(u) if u.0 > 0 => Ok(Support::Unit(u)),
            _ => Err(serde::de::Error::custom(format!(
                "off or unit1 … unit{}",
                MAX_UNITS - 1
            ))),
        }
    }
}

/// The order the units print in within a layer: the units listed first, in their order, then
/// the others by number. Written `unitN_first` when only N is out of its place (`unit0_first`:
/// by number), else as the list (`2,0,1`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnitOrder(Vec<UnitId>);

impl UnitOrder {
    /// Unit `u` first, then the others by number.
    pub fn unit_first(u: UnitId) -> UnitOrder {
        let mut all: Vec<UnitId> = UnitId::all(MAX_UNITS).filter(|&x| x != u).collect();
        all.insert(0, u);
        UnitOrder(all)
    }

    /// The units listed, in order, then the others by number; `None` when a unit is named
    /// twice or is beyond [`MAX_UNITS`].
    pub fn from_list(list: &[UnitId]) -> Option<UnitOrder> {
        let mut all = Vec::with_capacity(MAX_UNITS);
        for &u in list {
            if u.index() >= MAX_UNITS || all.contains(&u) {
                return None;
            }
            all.push(u);
        }
        all.extend(UnitId::all(MAX_UNITS).filter(|u| !list.contains(u)));
        Some(UnitOrder(all))
    }

    /// Every unit, in print order.
    pub fn units(&self) -> &[UnitId] {
        &self.0
    }

    /// Where unit `u` prints within a layer (0: first).
    pub fn rank(&self, u: UnitId) -> usize {
        self.0.iter().position(|&x| x == u).unwrap_or(usize::MAX)
    }

    /// The units it names ahead of their place by number (checked against `units`).
    pub fn named(&self) -> Vec<UnitId> {
        let mut named = self.0.clone();
        while named.len() > 1 && named[named.len() - 2] < named[named.len() - 1] {
            named.pop();
        }
        if named.len() == 1 {
            named.clear();
        }
        named
    }

    fn word(&self) -> String {
        match UnitId::all(MAX_UNITS).find(|&u| *self == UnitOrder::unit_first(u)) {
            Some(u) => format!("unit{}_first", u.0),
            None => {
                let list: Vec<String> = self.0.iter().map(|u| u.to_string()).collect();
                list.join(",")
            }
        }
    }

    fn parse(text: &str) -> Option<UnitOrder> {
        if let Some(u) = text.strip_suffix("_first").and_then(UnitId::parse_word) {
            return Some(UnitOrder::unit_first(u));
        }
        let list: Option<Vec<UnitId>> = text
            .split(',')
            .map(|n| n.trim().parse::<u8>().ok().map(UnitId))
            .collect();
        UnitOrder::from_list(&list?)
    }
}

impl Serialize for UnitOrder {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.word())
    }
}

impl<'de> Deserialize<'de> for UnitOrder {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let text = String::deserialize(d)?;
        UnitOrder::parse(&text).ok_or_else(|| {
            serde::de::Error::custom(format!(
                "unit0_first … unit{}_first, or a list of different units such as 2,0,1",
                MAX_UNITS - 1
            ))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn todays_words_keep_their_meaning() {
        let first = |t: &str| serde_json::from_value::<UnitOrder>(t.into()).unwrap();
        assert_eq!(first("unit0_first").units()[..2], [UnitId(0), UnitId(1)]);
        assert_eq!(
            first("unit1_first").units()[..3],
            [UnitId(1), UnitId(0), UnitId(2)]
        );
        assert_eq!(first("2,0,1").units()[..4], [2, 0, 1, 3].map(UnitId));
        assert_eq!(first("1,0"), first("unit1_first"));
        assert_eq!(serde_json::to_value(first("1,0")).unwrap(), "unit1_first");
        assert_eq!(first("2,0,1"), first("unit2_first"));
        assert_eq!(serde_json::to_value(first("2, 1")).unwrap(), "2,1,0,3");
        assert_eq!(first("2,1").named(), [2, 1, 0].map(UnitId));
        assert!(first("unit0_first").named().is_empty());
        assert_eq!(first("unit3_first").named(), [3, 0].map(UnitId));
        for bad in ["0,0", "5", "unit9_first", "", "a,b", "unit01_first"] {
            assert!(
                serde_json::from_value::<UnitOrder>(bad.into()).is_err(),
                "{bad}"
            );
        }
        let s = |t: &str| serde_json::from_value::<Support>(t.into());
        assert_eq!(s("unit1").unwrap(), Support::Unit(UnitId(1)));
        assert_eq!(s("unit3").unwrap().unit(), Some(UnitId(3)));
        assert!(s("unit0").is_err() && s("unit4").is_err() && s("on").is_err());
        assert_eq!(
            serde_json::to_value(Support::Unit(UnitId(2))).unwrap(),
            "unit2"
        );
    }
}
