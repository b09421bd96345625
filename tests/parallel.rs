//! `luxon render`'s parallel options in one process: decompositions, asynchronous and
//! synchronous output, statistics per thread. (MPI runs are in `tests/mpi.rs`.)

mod common;

use common::*;

fn render_to(dir: &std::path::Path, name: &str, extra: &[&str]) -> (Vec<u8>, String) {
    let out = dir.join(name);
    let scene = root().join("scenes/glass.ron");
    let mut args = vec![
        "render",
        scene.to_str().unwrap(),
        "--res",
        "97x61",
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend(extra);
    let o = run(&args);
    assert!(o.status.success(), "{extra:?}: {}", stderr(&o));
    (std::fs::read(&out).unwrap(), stderr(&o))
}

#[test]
fn every_decomposition_and_output_mode_writes_the_same_file() {
    let dir = temp_dir("parallel-cli");
    for ext in ["ppm", "png"] {
        // Synchronous output encodes through the writer plugins; asynchronous output streams
        // 8-bit PPM rows itself: both must give the same bytes.
        let name = format!("ref.{ext}");
        let (reference, _) = render_to(&dir, &name, &["--threads", "1", "--io", "sync"]);
        for how in ["pixel-cyclic", "scanline-cyclic", "block-cyclic", "dynamic"] {
            for io in ["async", "sync", "mpi-io"] {
                let name = format!("{how}-{io}.{ext}");
                let args = [
                    "--threads",
                    "2",
                    "--decomposition",
                    how,
                    "--block-size",
                    "7",
                    "--io",
                    io,
                ];
                let (img, _) = render_to(&dir, &name, &args);
                assert!(img == reference, "{how}, {io} output: {name} differs");
            }
        }
    }
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
}

#[test]
fn stats_show_the_work_of_every_thread() {
    let dir = temp_dir("parallel-stats");
    let (_, e) = render_to(
        &dir,
        "s.png",
        &[
            "--threads",
            "2",
            "--stats",
            "--decomposition",
            "scanline-cyclic",
        ],
    );
    assert!(e.contains("ranks            1"), "{e}");
    assert!(e.contains("threads          2 per rank"), "{e}");
    let rows: u64 = e
        .lines()
        .filter(|l| l.trim_start().starts_with("thread "))
        .map(|l| l.split_whitespace().nth(2).unwrap().parse::<u64>().unwrap())
        .sum();
    assert_eq!(rows, 61, "scanline-cyclic rows over the threads: {e}");
}
