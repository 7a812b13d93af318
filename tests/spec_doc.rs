//! docs/spec.md "5.4.1 Parameters" against the settings' schema: every setting has exactly one
//! row, under the heading of its group, with the schema's default, unit and range, in the
//! schema's order (the header's), and the tables name no setting the schema does not have.

use dropslice::base::settings::{Kind, MAX_UNITS, SettingSpec, schema};
use std::collections::HashMap;

/// One row of a parameter table: (group heading, name, default, unit, range).
type Row = (String, String, String, String, String);

/// The rows of the tables under "## 5.4.1" (up to the next `## ` heading).
fn rows(text: &str) -> Vec<Row> {
    let start = text
        .find("\n## 5.4.1 Parameters")
        .expect("docs/spec.md has a heading \"## 5.4.1 Parameters\"");
    let rest = &text[start + 1..];
    let end = rest[3..].find("\n## ").map_or(rest.len(), |i| i + 3);
    let mut group = String::new();
    let mut out = Vec::new();
    let mut per_unit: Vec<Row> = Vec::new();
    for line in rest[..end].lines() {
        if let Some(h) = line.strip_prefix("### ") {
            group = h.trim().to_string();
            continue;
        }
        let Some(cells) = line.strip_prefix("| `") else {
            flush(&mut per_unit, &mut out);
            continue;
        };
        let cells: Vec<&str> = cells.split(" | ").collect();
        assert!(cells.len() >= 5, "a row of 5 cells: {line}");
        let row = (
            group.clone(),
            cells[0].trim_end_matches('`').to_string(),
            cells[1].trim().to_string(),
            cells[2].trim().to_string(),
            units_spelled_out(cells[3].trim()),
        );
        if row.1.starts_with("unitN_") {
            per_unit.push(row);
        } else {
            flush(&mut per_unit, &mut out);
            out.push(row);
        }
    }
    flush(&mut per_unit, &mut out);
    out
}

/// A run of `unitN_<name>` rows stands for every unit N ≥ 1's settings, unit by unit, each
/// under the heading "Unit N" (the schema's order and groups).
fn flush(per_unit: &mut Vec<Row>, out: &mut Vec<Row>) {
    for n in 1..MAX_UNITS {
        for (_, name, default, unit, range) in per_unit.iter() {
            out.push((
                format!("Unit {n}"),
                name.replacen("unitN_", &format!("unit{n}_"), 1),
                default.clone(),
                unit.clone(),
                range.clone(),
            ));
        }
    }
    per_unit.clear();
}

/// A range cell with the units written short (`unit1 … unit3`, `unitN_first`) spelled out as
/// the schema lists its choices.
fn units_spelled_out(cell: &str) -> String {
    let last = MAX_UNITS - 1;
    let all = |pattern: &dyn Fn(usize) -> String, from: usize| {
        (from..MAX_UNITS)
            .map(pattern)
            .collect::<Vec<_>>()
            .join(" / ")
    };
    cell.replace(
        &format!("unit1 … unit{last}"),
        &all(&|n| format!("unit{n}"), 1),
    )
    .replace("unitN_first", &all(&|n| format!("unit{n}_first"), 0))
}

/// A number as the tables write it: no ".0", a minus sign (−) for negative values.
fn number(x: f64) -> String {
    let s = format!("{x}");
    s.replace('-', "−")
}

/// The range cell the schema implies.
fn range(spec: &SettingSpec) -> String {
    match spec.domain.kind {
        Kind::Bool => "true / false".into(),
        Kind::Enum | Kind::Order => spec.domain.choices.join(" / "),
        Kind::Number | Kind::Integer => {
            let (lo, hi) = (
                spec.domain.min.expect("a minimum"),
                spec.domain.max.expect("a maximum"),
            );
            let gt = if spec.domain.min_exclusive { "> " } else { "" };
            format!("{gt}{} … {}", number(lo), number(hi))
        }
    }
}

/// Whether the default cell says the schema's default.
fn same_default(cell: &str, value: &serde_json::Value) -> bool {
    match value {
        serde_json::Value::Number(n) => cell.parse::<f64>().ok() == n.as_f64(),
        serde_json::Value::Bool(b) => cell == b.to_string(),
        serde_json::Value::String(s) => cell == s,
        _ => false,
    }
}

/// The unit cell the schema implies.
fn unit(spec: &SettingSpec) -> String {
    match spec.domain.unit {
        "" => "–".into(),
        u => u.replace("x B", "× B"),
    }
}

#[test]
fn every_setting_is_in_docs_spec_with_the_schemas_default_unit_and_range() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/docs/spec.md");
    let text = std::fs::read_to_string(path).expect("docs/spec.md");
    let rows = rows(&text);
    let schema = schema();
    let mut seen: HashMap<&str, usize> = HashMap::new();
    let mut wrong = Vec::new();
    for (group, name, default, unit_cell, range_cell) in &rows {
        let Some(spec) = schema.iter().find(|s| s.name == name) else {
            wrong.push(format!("{name}: not a setting of the schema"));
            continue;
        };
        *seen.entry(spec.name).or_default() += 1;
        if group != spec.group {
            wrong.push(format!(
                "{name}: under \"### {group}\", the schema's group is \"{}\"",
                spec.group
            ));
        }
        if !same_default(default, &spec.default) {
            wrong.push(format!(
                "{name}: default {default}, the schema's is {}",
                spec.default
            ));
        }
        if *unit_cell != unit(spec) {
            wrong.push(format!(
                "{name}: unit {unit_cell}, the schema's is {}",
                unit(spec)
            ));
        }
        // A cell may add what else the value takes (`unit_order`: a list of units).
        let said = range_cell.split(", or ").next().unwrap_or_default();
        if said != range(spec) {
            wrong.push(format!(
                "{name}: range {range_cell}, the schema's is {}",
                range(spec)
            ));
        }
    }
    // The header lists the settings in the schema's order, and the page says it follows it.
    let order: Vec<&str> = rows.iter().map(|r| r.1.as_str()).collect();
    let expected: Vec<&str> = schema.iter().map(|s| s.name).collect();
    if wrong.is_empty() && order != expected {
        wrong.push(format!(
            "the rows are not in the schema's order:\n  docs:   {order:?}\n  schema: {expected:?}"
        ));
    }
    for spec in &schema {
        match seen.get(spec.name) {
            None => wrong.push(format!("{}: no row in docs/spec.md 5.4.1", spec.name)),
            Some(&n) if n > 1 => wrong.push(format!("{}: {n} rows", spec.name)),
            _ => {}
        }
    }
    assert!(
        wrong.is_empty(),
        "docs/spec.md \"5.4.1 Parameters\" disagrees with the settings' schema \
         (src/base/settings/schema.rs):\n{}",
        wrong.join("\n")
    );
}

#[test]
fn the_checks_see_a_wrong_row() {
    let spec = schema()
        .into_iter()
        .find(|s| s.name == "layer_height")
        .unwrap();
    assert_eq!(range(&spec), "0.0001 … 5");
    assert_eq!(unit(&spec), "mm");
    assert!(same_default("0.2", &spec.default));
    assert!(!same_default("0.25", &spec.default));
    let text = "x\n## 5.4.1 Parameters\n### Droplet\n| name | default |\n|---|---|\n\
                | `layer_height` | 0.2 | mm | > 0 … 5 | H |\n## 5.4.2 Processing\n\
                | `contours` | 2 | – | 0 … 100 | after the section |\n";
    let r = rows(text);
    assert_eq!(r.len(), 1, "{r:?}");
    assert_eq!(r[0].0, "Droplet");
    assert_eq!(r[0].1, "layer_height");
}
