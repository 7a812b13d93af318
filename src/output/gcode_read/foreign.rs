//! Another printer's G-code: its commands found and named (`M140`, `G1 … E…`), so the reader
//! refuses a filament or CNC file as such.

/// A filament (FDM) or CNC command: `M104`, `G1`, `G28`, `G92.1` — a G or M and a number.
fn machine_command(word: &str) -> bool {
    let Some(number) = word.strip_prefix(['G', 'g', 'M', 'm']) else {
        return false;
    };
    let (int, frac) = number.split_once('.').unwrap_or((number, "0"));
    let digits = |t: &str| !t.is_empty() && t.len() <= 5 && t.bytes().all(|b| b.is_ascii_digit());
    digits(int) && digits(frac)
}

/// The message for G-code of another kind of printer with the commands `names`.
pub(super) fn foreign_message(names: &[String]) -> String {
    format!(
        "this is G-code for another kind of printer (it has {}): dropslice reads the droplet printer's code it writes (G01 travel, G25 droplet line, G26 droplet); open the model (STL, OBJ or 3MF) and slice it instead",
        names.join(", ")
    )
}

/// The distinct foreign commands of a file: `first`, then those of the lines of `ahead` (its
/// first 64 kB): at most four, one that feeds filament (`G1 … E…`) among them when any does.
pub(super) fn foreign_names(first: &str, ahead: &str) -> Vec<String> {
    let mut end = ahead.len().min(1 << 16);
    while !ahead.is_char_boundary(end) {
        end -= 1;
    }
    let mut names = vec![first.to_string()];
    let mut feeds = first.contains('E').then(|| first.to_string());
    for name in ahead[..end].lines().filter_map(foreign_name) {
        if name.ends_with("E…") && feeds.is_none() {
            feeds = Some(name.clone());
        }
        if names.len() < 4 && !names.contains(&name) {
            names.push(name);
        }
    }
    if let Some(f) = feeds
        && !names.contains(&f)
    {
        if names.len() < 4 {
            names.push(f);
        } else {
            names[3] = f;
        }
    }
    names
}

/// How the foreign commands of a line are named: the command word as written in upper case
/// (`M140`), and `G1 … E…` for a move that feeds filament.
pub(super) fn foreign_name(line: &str) -> Option<String> {
    let line = line.split(';').next().unwrap_or("").trim();
    let mut words = line.split_whitespace();
    let first = words.next()?;
    if !machine_command(first) {
        return None;
    }
    let first = first.to_ascii_uppercase();
    // A move (G0 … G3) with an E word feeds filament; `G92 E0` only sets the position.
    let moves = matches!(
        first.as_str(),
        "G0" | "G1" | "G2" | "G3" | "G00" | "G02" | "G03"
    );
    let feeds = moves && words.any(|w| w.starts_with(['E', 'e']));
    Some(if feeds {
        format!("{first} … E…")
    } else {
        first
    })
}
