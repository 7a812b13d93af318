//! The analysis takes memory in proportion to the part, not to its bounding box: `--report` on
//! two 1 mm cubes 1 m apart once took 4.5 GB (its raster spanned the layer's bounding box) and
//! 3 m apart it could not allocate at all; the page's coverage mask was a dense grid over the
//! same box. Now rasters, spheroid maps and masks are stored in tiles near the parts only.
#![cfg(not(target_arch = "wasm32"))] // native only: `wasm-pack test` builds every test target

mod common;

use dropslice::Settings;
use dropslice::analysis::{
    Grid3, HeightMap, Raster, analyse_layer, analyse_layer_with_mask, footprint_diameter,
    slab_voids,
};
use dropslice::base::geom::{Point, Shapes};

/// A `side` mm square at (x, y) filled with droplets on a square lattice of pitch B (their
/// gaps are voids).
fn square(x: f64, y: f64, side: f64, b: f64) -> (Shapes, Vec<Point>) {
    let outer = [[x, y], [x + side, y], [x + side, y + side], [x, y + side]];
    let region = vec![dropslice::base::geom::Shape::new(
        outer.map(Into::into).into(),
        vec![],
    )];
    let n = (side / b) as usize;
    let mut pts = Vec::new();
    for i in 0..n {
        for j in 0..n {
            pts.push([x + (i as f64 + 0.5) * b, y + (j as f64 + 0.5) * b].into());
        }
    }
    (region, pts)
}

#[test]
fn parts_far_apart_take_memory_for_the_parts_only() {
    let s = Settings::default();
    let b = s.droplet_width();
    let (ra, pa) = square(0.0, 0.0, 2.0, b);
    // About 1 m apart, a whole number of droplet widths: both squares lie alike on the grids.
    let apart = (1000.0 / b).round() * b;
    let (rb, pb) = square(apart, apart, 2.0, b);
    let region: Shapes = ra.iter().chain(&rb).cloned().collect();
    let pts: Vec<Point> = pa.iter().chain(&pb).copied().collect();

    // The figures: twice those of one square.
    let one = analyse_layer(&common::droplet_plan(&pa), &ra, &s);
    let (two, mask) = analyse_layer_with_mask(&common::droplet_plan(&pts), &region, &s, b / 4.0);
    assert!((two.region_area - 8.0).abs() < 1e-9, "{}", two.region_area);
    let close = |a: f64, b: f64| (a - b).abs() <= 0.01 * b.abs().max(1e-3);
    assert!(
        close(two.covered_area, 2.0 * one.covered_area),
        "{two:?}\n{one:?}"
    );
    assert!(
        close(two.void_area, 2.0 * one.void_area),
        "{two:?}\n{one:?}"
    );
    assert!(
        close(two.overfill_area, 2.0 * one.overfill_area),
        "{two:?}\n{one:?}"
    );
    assert!((two.boundary_deviation - one.boundary_deviation).abs() < b / 10.0);

    // The raster: a 1 m square at B/10 × B/40 would take 2.3 GB; the two squares take little.
    let raster = Raster::from_centres(0, 0.0, &pts, &region, &s);
    let bytes = 8 * raster.stored_words();
    assert!(bytes < 2_000_000, "raster of {bytes} bytes");
    assert_eq!(raster.analysis(), two);

    // The mask: tiles only near the two squares, their void shares adding up to the void area.
    let cells: usize = mask.tiles.iter().map(|t| t.rect.cells()).sum();
    let area = cells as f64 * mask.cell * mask.cell;
    assert!(area < 100.0, "mask tiles over {area} mm²");
    let mut void = 0.0;
    for t in &mask.tiles {
        let n = t.rect.cells();
        assert_eq!((t.void.len(), t.overfill.len(), t.covered.len()), (n, n, n));
        let o = mask.tile_origin(t);
        let far = [
            o[0] + t.rect.width as f64 * mask.cell,
            o[1] + t.rect.height as f64 * mask.cell,
        ];
        let near =
            |c: f64| o[0] > c - 10.0 && o[1] > c - 10.0 && far[0] < c + 12.0 && far[1] < c + 12.0;
        assert!(near(0.0) || near(apart), "tile {o:?}..{far:?}");
        void += t.void.iter().map(|&v| v as f64 / 255.0).sum::<f64>() * mask.cell * mask.cell;
    }
    assert!(
        (void - two.void_area).abs() < 0.05 * two.void_area,
        "{void} vs {}",
        two.void_area
    );
    // Tiles do not overlap, in rows then columns.
    for (a, b) in mask.tiles.iter().zip(mask.tiles.iter().skip(1)) {
        let (a, b) = (a.rect, b.rect);
        assert!((a.row, a.col) < (b.row, b.col));
        assert!(b.row >= a.end_row() || b.col >= a.end_col());
    }

    // The 3D estimate's spheroid map: a 1 m square at B/3 would take 800 MB.
    let grid = Grid3 {
        origin: [-1.0, -1.0].into(),
        cell: b / 3.0,
    };
    let d = footprint_diameter(&s);
    let map = HeightMap::new(&pts, &grid, d);
    assert!(map.stored_cells() < 50_000, "{} cells", map.stored_cells());
    let (vol, void) = slab_voids(&region, &grid, Some(&map), &map, Some(&map), &s);
    let one_map = HeightMap::new(&pa, &grid, d);
    let (vol1, void1) = slab_voids(&ra, &grid, Some(&one_map), &one_map, Some(&one_map), &s);
    assert!(
        close(vol, 2.0 * vol1) && close(void, 2.0 * void1),
        "{vol} {void} {vol1} {void1}"
    );
}

/// A binary STL of axis-aligned boxes (min, max), 12 facets each.
fn boxes_stl(boxes: &[([f32; 3], [f32; 3])]) -> Vec<u8> {
    let tris: Vec<_> = boxes
        .iter()
        .flat_map(|&(lo, hi)| common::cuboid(lo, hi))
        .collect();
    common::stl_bytes(&tris)
}

/// Runs `dropslice MODEL -o OUT --report REPORT` on `stl`: the report, and the process's peak
/// resident memory in bytes (from wait4).
#[cfg(target_os = "linux")]
fn report_and_peak_memory(stl: &[u8]) -> (serde_json::Value, u64) {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("model.stl");
    std::fs::write(&model, stl).unwrap();
    let (gco, json) = (dir.path().join("out.gco"), dir.path().join("report.json"));
    let stderr = std::fs::File::create(dir.path().join("stderr.txt")).unwrap();
    // Reaped by wait4 below (which gives its peak memory), not by `Child::wait`.
    #[allow(clippy::zombie_processes)]
    let child = std::process::Command::new(env!("CARGO_BIN_EXE_dropslice"))
        .arg(&model)
        .arg("-o")
        .arg(&gco)
        .arg("--report")
        .arg(&json)
        // parts metres apart: past the default plate, sliced where they lie
        .args(["--set", "allow_off_plate=true"])
        .stderr(stderr)
        .spawn()
        .unwrap();
    let pid = child.id() as libc::pid_t;
    let mut status = 0;
    // SAFETY: a zeroed rusage is valid; wait4 reaps our own child, which `child` never waits for.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    let got = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
    assert_eq!(got, pid, "wait4: {}", std::io::Error::last_os_error());
    let log = std::fs::read_to_string(dir.path().join("stderr.txt")).unwrap();
    assert!(
        libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0,
        "dropslice failed (status {status:#x}): {log}"
    );
    let report = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    // ru_maxrss is in kilobytes on Linux.
    (report, usage.ru_maxrss as u64 * 1024)
}

#[cfg(target_os = "linux")]
#[test]
fn two_small_cubes_metres_apart_are_analysed_in_little_memory() {
    let cube = |x: f32| ([x, x, 0.0], [x + 1.0, x + 1.0, 1.0]);
    let (single, _) = report_and_peak_memory(&boxes_stl(&[cube(0.0)]));
    let coverage = single["part"]["coverage"].as_f64().unwrap();
    for apart in [1000.0, 3000.0] {
        let (report, peak) = report_and_peak_memory(&boxes_stl(&[cube(0.0), cube(apart)]));
        let part = &report["part"];
        let figure = |name: &str| part[name].as_f64().unwrap();
        assert!(peak < 400 << 20, "{apart} mm apart: peak {} MB", peak >> 20);
        assert_eq!(part["layers"], 5, "{part}");
        assert!((figure("region_area") - 10.0).abs() < 1e-6, "{part}");
        // The far cube is sliced at large coordinates (a droplet more or less), so about, not
        // exactly, the single cube's figures.
        assert!(
            (figure("coverage") - coverage).abs() < 0.02,
            "{apart} mm apart: coverage {} vs {coverage} for one cube",
            figure("coverage")
        );
        assert!((0.1..0.4).contains(&figure("void_fraction")), "{part}");
        assert!(figure("max_boundary_deviation") < 0.208, "{part}");
        assert!(
            part["largest_void"]["area"].as_f64().unwrap() < 0.1,
            "{part}"
        );
        eprintln!("{apart} mm apart: peak {:.1} MB", peak as f64 / 1048576.0);
    }
}
