//! `dropslice calibrate PART.gco --mass GRAMS [--density G_CM3]`: the droplet size from a
//! printed part's mass and its code.

use crate::cli::CalibrateArgs;
use crate::files::open_regular;
use dropslice::base::error::quote;
use dropslice::output::calibrate::{CountSource, calibrate_read};
use dropslice::output::gcode_read::{GcodeReader, MAX_LINE_CHARS};
use std::path::Path;
use std::process::ExitCode;

const USAGE: &str = "usage: dropslice calibrate PART.gco --mass GRAMS [--density G_CM3]";

pub fn main(args: CalibrateArgs) -> ExitCode {
    match calibrate(args) {
        Ok(text) => {
            println!("{text}");
            ExitCode::SUCCESS
        }
        Err(msg) => {
            eprintln!("dropslice calibrate: {msg}");
            ExitCode::from(2)
        }
    }
}

/// The figures, or why not.
fn calibrate(args: CalibrateArgs) -> Result<String, String> {
    let number = |opt: &str, v: &str| -> Result<f64, String> {
        v.trim()
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| format!("{opt} {}: not a number", quote(v)))
    };
    let mass = args
        .mass
        .as_deref()
        .map(|v| number("--mass", v))
        .transpose()?;
    let density = args
        .density
        .as_deref()
        .map(|v| number("--density", v))
        .transpose()?;
    let file = args
        .file
        .ok_or_else(|| format!("no .gco file given ({USAGE})"))?;
    let mass = mass.ok_or_else(|| format!("--mass GRAMS is needed ({USAGE})"))?;
    let reader = read_counting(&file)?;
    let c =
        calibrate_read(&reader, mass, density).map_err(|e| format!("{}: {e}", file.display()))?;
    Ok(format!(
        "{}\n  droplets          {} ({})\n  droplet volume    {:.5} mm³ (m / (N ρ), ρ = {} g/cm³)\n  cell B²H          {:.5} mm³ (H = {} mm, droplet_aspect = {})\n  filling degree    {:.3}\n  droplet_aspect    {:.3} suggested (now {})",
        c.explanation,
        c.droplets,
        match c.count_source {
            CountSource::Header => "from the header",
            _ => "counted from the commands",
        },
        c.droplet_volume_mm3,
        c.density_g_cm3,
        c.cell_volume_mm3,
        c.layer_height,
        c.current_droplet_aspect,
        c.filling_degree,
        c.suggested_droplet_aspect,
        c.current_droplet_aspect
    ))
}

/// Reads a `.gco` file through the core's reader (counting only), in pieces of whole lines.
fn read_counting(path: &Path) -> Result<GcodeReader, String> {
    use std::io::Read;
    let shown = path.display();
    let (mut f, _) = open_regular(path)?;
    let mut r = GcodeReader::counting();
    let mut buf: Vec<u8> = Vec::new();
    let mut chunk = vec![0u8; 1 << 20];
    loop {
        let n = f
            .read(&mut chunk)
            .map_err(|e| format!("cannot read {shown}: {e}"))?;
        if n == 0 {
            break;
        }
        buf.extend_from_slice(&chunk[..n]);
        let Some(nl) = buf.iter().rposition(|&c| c == b'\n') else {
            if buf.len() > 4 * MAX_LINE_CHARS {
                return Err(format!(
                    "{shown}: a line is longer than {MAX_LINE_CHARS} characters: not a G-code file"
                ));
            }
            continue;
        };
        let text = std::str::from_utf8(&buf[..=nl])
            .map_err(|_| format!("{shown}: not a text file (a .gco file is ASCII text)"))?;
        r.feed(text).map_err(|e| format!("{shown}: {e}"))?;
        while r.take_layer().is_some() {}
        buf.drain(..=nl);
    }
    let rest = std::str::from_utf8(&buf)
        .map_err(|_| format!("{shown}: not a text file (a .gco file is ASCII text)"))?;
    r.feed(rest).map_err(|e| format!("{shown}: {e}"))?;
    r.finish().map_err(|e| format!("{shown}: {e}"))?;
    while r.take_layer().is_some() {}
    Ok(r)
}
