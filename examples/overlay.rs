//! Renders a layer's coverage as a PNG: droplets inside the region grey, voids red, overfill
//! blue, outside white. `cargo run --release --example overlay -- MODEL.stl LAYER OUT.png
//! [x0 y0 x1 y1] [--zoom N] [--set name=value]...` (layer from 1; window in mm, default the
//! whole layer; pixels of B/10, each drawn N × N; `--below` marks the droplet centres of the
//! layer below with dark dots).
//! The PNG is written with stored (uncompressed) deflate blocks: no dependency needed.
// Native tools: on wasm32 (`wasm-pack test` builds every target) the example is empty.
#![cfg_attr(target_arch = "wasm32", no_main)]
#![cfg(not(target_arch = "wasm32"))]
use dropslice::analysis::analyse_layer_with_mask;
use dropslice::{Job, Settings};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut s = Settings::default();
    let mut pos = Vec::new();
    let mut zoom = 1usize;
    let mut below = false;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        if a == "--below" {
            below = true;
        } else if a == "--zoom" {
            zoom = it.next().expect("zoom").parse().expect("zoom factor");
        } else if a == "--set" {
            let kv = it.next().expect("name=value");
            let (k, v) = kv.split_once('=').expect("name=value");
            s.set(k, v).expect("setting");
        } else {
            pos.push(a.clone());
        }
    }
    let bytes = std::fs::read(&pos[0]).expect("model");
    let layer: usize = pos[1].parse().expect("layer number");
    let out = &pos[2];
    let job = Job::new(&bytes, &pos[0], s.clone()).expect("job");
    let i = layer - 1;
    let region = job.section(i).region;
    let plan = dropslice::slicing::plan::plan_layer(&region, i, &s);
    let b = s.droplet_width();
    let (a, m) = analyse_layer_with_mask(&plan, &region, &s, b / 10.0);
    eprintln!("{}", serde_json::to_string(&a).unwrap());
    // The window, in mask cells (the mask holds tiles only where the part is).
    let (width, height) = m.size();
    let (mut c0, mut r0, mut c1, mut r1) = (0, 0, width, height);
    if pos.len() >= 7 {
        let w: Vec<f64> = pos[3..7].iter().map(|v| v.parse().unwrap()).collect();
        let col = |x: f64| (((x - m.origin[0]) / m.cell).max(0.0) as usize).min(width);
        let row = |y: f64| (((y - m.origin[1]) / m.cell).max(0.0) as usize).min(height);
        (c0, r0, c1, r1) = (col(w[0]), row(w[1]), col(w[2]), row(w[3]));
    }
    let (w, h) = (c1 - c0, r1 - r0);
    // The window's shares [void, overfill, covered], row-major from its lowest row.
    let mut shares = vec![[0u8; 3]; w * h];
    for t in &m.tiles {
        let rect = t.rect;
        for r in rect.row.max(r0)..rect.end_row().min(r1) {
            for c in rect.col.max(c0)..rect.end_col().min(c1) {
                let i = rect.index(c, r);
                shares[(r - r0) * w + c - c0] = [t.void[i], t.overfill[i], t.covered[i]];
            }
        }
    }
    // Droplet centres of the layer below, as dark dots.
    let mut dots = std::collections::HashSet::new();
    if below && i > 0 {
        let region = job.section(i - 1).region;
        let plan = dropslice::slicing::plan::plan_layer(&region, i - 1, &s);
        for p in dropslice::analysis::droplet_centres(&plan, b) {
            let c = ((p[0] - m.origin[0]) / m.cell) as i64;
            let r = ((p[1] - m.origin[1]) / m.cell) as i64;
            for dr in -1..=1 {
                for dc in -1..=1 {
                    dots.insert((r + dr, c + dc));
                }
            }
        }
    }
    let mut rgb = Vec::with_capacity(w * h * 3 * zoom * zoom);
    for r in (r0..r1).rev().flat_map(|r| std::iter::repeat_n(r, zoom)) {
        for c in (c0..c1).flat_map(|c| std::iter::repeat_n(c, zoom)) {
            if dots.contains(&(r as i64, c as i64)) {
                rgb.extend([20, 20, 20]);
                continue;
            }
            let [v, o, cv] = shares[(r - r0) * w + c - c0].map(|x| x as f64 / 255.0);
            let white = (1.0 - v - o - cv).max(0.0);
            // white, red (void), blue (overfill), grey (covered)
            let px = [
                white * 255.0 + v * 220.0 + o * 40.0 + cv * 150.0,
                white * 255.0 + v * 20.0 + o * 90.0 + cv * 150.0,
                white * 255.0 + v * 20.0 + o * 230.0 + cv * 150.0,
            ];
            rgb.extend(px.map(|x| x.round().clamp(0.0, 255.0) as u8));
        }
    }
    std::fs::write(out, png((w * zoom) as u32, (h * zoom) as u32, &rgb)).expect("write png");
}

fn crc32(data: &[u8]) -> u32 {
    let mut c = 0xffff_ffffu32;
    for &b in data {
        c ^= b as u32;
        for _ in 0..8 {
            c = if c & 1 != 0 {
                0xedb8_8320 ^ (c >> 1)
            } else {
                c >> 1
            };
        }
    }
    !c
}

fn png(w: u32, h: u32, rgb: &[u8]) -> Vec<u8> {
    let mut raw = Vec::with_capacity((w as usize * 3 + 1) * h as usize);
    for row in rgb.chunks(w as usize * 3) {
        raw.push(0);
        raw.extend_from_slice(row);
    }
    // zlib stream of stored blocks.
    let mut z = vec![0x78, 0x01];
    let chunks: Vec<&[u8]> = raw.chunks(65535).collect();
    for (i, c) in chunks.iter().enumerate() {
        z.push(u8::from(i + 1 == chunks.len()));
        let n = c.len() as u16;
        z.extend(n.to_le_bytes());
        z.extend((!n).to_le_bytes());
        z.extend_from_slice(c);
    }
    let (mut a, mut b) = (1u32, 0u32);
    for &x in &raw {
        a = (a + x as u32) % 65521;
        b = (b + a) % 65521;
    }
    z.extend(((b << 16) | a).to_be_bytes());
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut chunk = |kind: &[u8], data: &[u8]| {
        out.extend((data.len() as u32).to_be_bytes());
        let mut body = kind.to_vec();
        body.extend_from_slice(data);
        out.extend_from_slice(&body);
        out.extend(crc32(&body).to_be_bytes());
    };
    let mut ihdr = Vec::new();
    ihdr.extend(w.to_be_bytes());
    ihdr.extend(h.to_be_bytes());
    ihdr.extend([8, 2, 0, 0, 0]);
    chunk(b"IHDR", &ihdr);
    chunk(b"IDAT", &z);
    chunk(b"IEND", &[]);
    out
}
