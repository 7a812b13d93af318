//! What the examples that print a Markdown table over model files share.

use std::path::Path;

/// Prints a Markdown table's header row, `columns` (separated by " | "), and the row under it.
pub fn header(columns: &str) {
    println!("| {columns} |");
    println!("|{}", "---|".repeat(columns.split(" | ").count()));
}

/// The bytes of the model file at `path` and the name a row gives it: its file name, or
/// (`stem`) the file name without its extension.
pub fn read_model(path: &str, stem: bool) -> (Vec<u8>, String) {
    let bytes = std::fs::read(path).expect("read model");
    let p = Path::new(path);
    let name = if stem { p.file_stem() } else { p.file_name() };
    (bytes, name.unwrap().to_string_lossy().into_owned())
}
