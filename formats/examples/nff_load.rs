//! Times NFF loading, and writes big NFF test inputs.
//!
//! ```sh
//! # ~1.47 M triangles, 250 MB: ten copies of teapot48's patches side by side
//! cargo run --release -p luxon-formats --example nff_load -- \
//!     --make-big ../shared/spd/teapot48.nff.gz /tmp/teapot-big.nff --copies 10
//! # median of 5 loads
//! cargo run --release -p luxon-formats --example nff_load -- /tmp/teapot-big.nff --runs 5
//! ```

use std::io::{BufRead, BufReader, BufWriter, Read, Write};
use std::path::Path;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("--make-big") {
        let (src, out) = (&args[1], &args[2]);
        let copies = flag(&args, "--copies").unwrap_or(10);
        make_big(Path::new(src), Path::new(out), copies);
        return;
    }
    let Some(path) = args.first() else {
        eprintln!("usage: nff_load FILE [--runs N] | --make-big SRC OUT [--copies K]");
        std::process::exit(2);
    };
    let runs = flag(&args, "--runs").unwrap_or(5);
    let mut times = Vec::new();
    for run in 0..runs {
        let t = Instant::now();
        let imported = luxon_formats::nff::import(Path::new(path)).unwrap_or_else(|e| {
            eprintln!("{e}");
            std::process::exit(1)
        });
        let secs = t.elapsed().as_secs_f64();
        if run == 0 {
            let s = imported.stats;
            println!(
                "{path}: {} lines, {} spheres, {} cones, {} polygons + {} patches = {} triangles, \
                 {} lights, {} materials, {} geometry groups",
                s.lines,
                s.spheres,
                s.cones,
                s.polygons,
                s.patches,
                s.triangles,
                s.lights,
                s.materials,
                imported.desc.inline.len()
            );
        }
        drop(imported);
        println!("run {}: {:.3} s", run + 1, secs);
        times.push(secs);
    }
    times.sort_by(f64::total_cmp);
    println!(
        "median {:.3} s over {} runs ({} threads)",
        times[times.len() / 2],
        runs,
        rayon::current_num_threads()
    );
}

fn flag(args: &[String], name: &str) -> Option<usize> {
    let i = args.iter().position(|a| a == name)?;
    args.get(i + 1)?.parse().ok()
}

/// Writes `copies` copies of the source's polygons and patches in a row along x (the view,
/// lights and materials once), so the file loads like one big SPD teapot.
fn make_big(src: &Path, out: &Path, copies: usize) {
    let file = std::fs::File::open(src).expect("cannot open the source");
    let mut reader: Box<dyn Read> = if src.to_string_lossy().ends_with(".gz") {
        Box::new(flate2::read::MultiGzDecoder::new(file))
    } else {
        Box::new(file)
    };
    let mut text = String::new();
    reader
        .read_to_string(&mut text)
        .expect("cannot read the source");
    let mut w =
        BufWriter::with_capacity(1 << 20, std::fs::File::create(out).expect("cannot create"));
    for copy in 0..copies {
        let dx = copy as f64 * 8.0;
        let mut in_view = false;
        for line in BufReader::new(text.as_bytes()).lines() {
            let line = line.unwrap();
            let first = line.split_whitespace().next().unwrap_or("");
            let numeric = first.starts_with(|c: char| c.is_ascii_digit() || c == '-' || c == '.');
            if first == "v" {
                in_view = true;
            } else if !numeric
                && !["from", "at", "up", "angle", "hither", "resolution"].contains(&first)
            {
                in_view = false;
            }
            let header = in_view || ["v", "b", "l"].contains(&first);
            if header {
                if copy == 0 {
                    writeln!(w, "{line}").unwrap();
                }
            } else if numeric {
                let mut v: Vec<f64> = line
                    .split_whitespace()
                    .map(|t| t.parse().unwrap())
                    .collect();
                v[0] += dx;
                let s: Vec<String> = v.iter().map(|x| format!("{:.5}", x)).collect();
                writeln!(w, "{}", s.join(" ")).unwrap();
            } else {
                writeln!(w, "{line}").unwrap();
            }
        }
    }
    w.flush().unwrap();
}
