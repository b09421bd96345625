//! Our reader against OpenVDB itself, live: when Debian's `python3-openvdb` is installed, every
//! fixture's first float grid is sampled by pyopenvdb (tests/fixtures/oracle.py) on a lattice
//! around its active box and compared with `read_grid`, value and active flag. Without
//! pyopenvdb the test says so and checks nothing more (the committed `.ref` files, written by
//! OpenVDB, are checked by tests/fixtures.rs in every case).

use luxon_volume_vdb::read_grid;
use std::path::Path;
use std::process::Command;

#[test]
fn every_fixture_matches_pyopenvdb_when_installed() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures");
    let python = "/usr/bin/python3";
    let available = Command::new(python)
        .args(["-c", "import pyopenvdb"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !available {
        eprintln!("pyopenvdb oracle: skipped, {python} cannot import pyopenvdb");
        return;
    }
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.ends_with(".vdb"))
        .collect();
    files.sort();
    let out = Command::new(python)
        .arg(dir.join("oracle.py"))
        .args(&files)
        .current_dir(&dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let (mut grids, mut voxels) = (0, 0);
    let mut current = None;
    for line in text.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w[0] {
            "grid" => {
                let bytes = std::fs::read(dir.join(w[1])).unwrap();
                let g = read_grid(&bytes, Some(w[2]))
                    .unwrap_or_else(|e| panic!("{} grid {}: {e}", w[1], w[2]));
                assert_eq!(
                    g.active_voxel_count(),
                    w[3].parse::<u64>().unwrap(),
                    "{}: active voxels",
                    w[1]
                );
                current = Some((w[1].to_string(), g));
                grids += 1;
            }
            "v" => {
                let (file, g) = current.as_ref().unwrap();
                let ijk = [w[1], w[2], w[3]].map(|c| c.parse::<i32>().unwrap());
                let want: f64 = w[4].parse().unwrap();
                let on = w[5] == "1";
                let (got, got_on) = g.value(ijk);
                assert!(
                    got as f64 == want || (got as f64 - want).abs() <= 1e-6 * want.abs(),
                    "{file} {ijk:?}: {got} vs OpenVDB's {want}"
                );
                assert_eq!(got_on, on, "{file} {ijk:?}: active flag");
                voxels += 1;
            }
            _ => panic!("unexpected oracle line {line}"),
        }
    }
    assert!(
        grids >= 8 && voxels > 10_000,
        "{grids} grids, {voxels} voxels"
    );
    eprintln!("pyopenvdb oracle: {grids} grids, {voxels} voxels agree");
}
