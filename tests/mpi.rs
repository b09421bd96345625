//! MPI runs of the `luxon` binary under `mpirun` (feature `mpi`; OpenMPI): bitwise-identical
//! images from any ranks × threads and decomposition, MPI-IO output equal to gathered output,
//! and a failing rank ending the whole job quickly. Every mpirun has a deadline.

mod common;

#[cfg(not(feature = "mpi"))]
#[test]
fn without_mpi_several_ranks_are_refused_and_mpi_scenes_render_here() {
    use common::*;
    eprintln!(
        "skipped: the MPI tests need the `mpi` feature: cargo test --workspace --features mpi"
    );
    let dir = temp_dir("no-mpi");
    let out = dir.join("o.png");
    let scene = root().join("scenes/glass.ron");
    let args = [
        "render",
        scene.to_str().unwrap(),
        "--res",
        "24x16",
        "--parallel",
        "hybrid",
        "-o",
        out.to_str().unwrap(),
    ];
    // What mpirun would set for the second of two ranks.
    let o = luxon()
        .args(args)
        .env("OMPI_COMM_WORLD_SIZE", "2")
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(stderr(&o).contains("built without MPI"), "{}", stderr(&o));
    let o = luxon().args(args).output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.exists());
}

#[cfg(feature = "mpi")]
mod with_mpi {
    use super::common::*;
    use std::path::{Path, PathBuf};
    use std::process::{Command, Output, Stdio};
    use std::time::Duration;

    const DEADLINE: Duration = Duration::from_secs(60);

    fn scene() -> String {
        root().join("scenes/glass.ron").display().to_string()
    }

    /// Runs `mpirun -np ranks luxon args...`, killed after the deadline (mpirun's own
    /// `--timeout` too, so a hung job cannot outlive the test).
    fn mpirun(ranks: usize, args: &[&str], env: &[(&str, &str)]) -> (Output, Duration) {
        ensure_plugins();
        let mut cmd = Command::new("mpirun");
        cmd.env("OMPI_ALLOW_RUN_AS_ROOT", "1")
            .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
            .args(["--oversubscribe", "--bind-to", "none", "--timeout"])
            .arg(DEADLINE.as_secs().to_string());
        for (k, v) in env {
            cmd.env(k, v).args(["-x", k]);
        }
        cmd.arg("-np")
            .arg(ranks.to_string())
            .arg(env!("CARGO_BIN_EXE_luxon"))
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        run_with_deadline(
            &mut cmd,
            DEADLINE + Duration::from_secs(15),
            &format!("mpirun -np {ranks} {args:?}"),
        )
    }

    fn render_mpi(ranks: usize, dir: &Path, tag: &str, extra: &[&str]) -> (Vec<u8>, Vec<u8>) {
        let (exr, ppm) = (
            dir.join(format!("{tag}.exr")),
            dir.join(format!("{tag}.ppm")),
        );
        let s = scene();
        let mut args = vec!["render", &s, "--res", "97x61", "-o"];
        args.extend([exr.to_str().unwrap(), "-o", ppm.to_str().unwrap()]);
        args.extend(extra);
        let (o, _) = mpirun(ranks, &args, &[]);
        assert!(o.status.success(), "-np {ranks} {extra:?}: {}", stderr(&o));
        (std::fs::read(exr).unwrap(), std::fs::read(ppm).unwrap())
    }

    /// One thread in one process, no MPI: the reference (float EXR for bitwise comparison).
    fn reference(dir: &Path) -> (Vec<u8>, Vec<u8>) {
        let (exr, ppm): (PathBuf, PathBuf) = (dir.join("ref.exr"), dir.join("ref.ppm"));
        let s = scene();
        let o = run(&[
            "render",
            &s,
            "--res",
            "97x61",
            "--threads",
            "1",
            "-o",
            exr.to_str().unwrap(),
            "-o",
            ppm.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        (std::fs::read(exr).unwrap(), std::fs::read(ppm).unwrap())
    }

    #[test]
    fn ranks_threads_and_decompositions_agree_bitwise() {
        let dir = temp_dir("mpi-bitwise");
        let want = reference(&dir);
        let runs: &[(usize, &[&str])] = &[
            (1, &["--parallel", "mpi"]),
            (2, &[]),
            (3, &["--parallel", "hybrid", "--threads", "2"]),
            (2, &["--parallel", "mpi", "--decomposition", "pixel-cyclic"]),
            (
                2,
                &["--parallel", "mpi", "--decomposition", "scanline-cyclic"],
            ),
            (3, &["--decomposition", "block-cyclic", "--block-size", "7"]),
            (
                3,
                &[
                    "--parallel",
                    "hybrid",
                    "--threads",
                    "2",
                    "--block-size",
                    "5",
                ],
            ),
            (2, &["--io", "sync"]),
        ];
        for (i, (ranks, extra)) in runs.iter().enumerate() {
            let got = render_mpi(*ranks, &dir, &format!("run{i}"), extra);
            assert!(got.0 == want.0, "-np {ranks} {extra:?}: EXR differs");
            assert!(got.1 == want.1, "-np {ranks} {extra:?}: PPM differs");
        }
    }

    #[test]
    fn mpi_io_output_equals_gathered_output() {
        let dir = temp_dir("mpi-io");
        let (_, gathered) = render_mpi(2, &dir, "gathered", &[]);
        for (ranks, how) in [(2, "dynamic"), (3, "pixel-cyclic"), (3, "scanline-cyclic")] {
            let ppm = dir.join(format!("io-{ranks}-{how}.ppm"));
            let s = scene();
            let args = [
                "render",
                &s,
                "--res",
                "97x61",
                "--io",
                "mpi-io",
                "--decomposition",
                how,
                "-o",
                ppm.to_str().unwrap(),
            ];
            let (o, _) = mpirun(ranks, &args, &[]);
            assert!(o.status.success(), "{}", stderr(&o));
            let written = std::fs::read(&ppm).unwrap();
            assert!(written == gathered, "MPI-IO -np {ranks} {how}: PPM differs");
        }
        let temps: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
            .collect();
        assert!(temps.is_empty(), "{temps:?}");
    }

    #[test]
    fn a_failing_rank_ends_the_job_with_its_cause() {
        let dir = temp_dir("mpi-fail");
        let out = dir.join("never.ppm");
        let s = scene();
        let args = [
            "render",
            &s,
            "--res",
            "97x61",
            "--block-size",
            "8",
            "-o",
            out.to_str().unwrap(),
        ];
        for (rank, how, says) in [
            ("1", "error", "luxon: error: rank 1: injected failure"),
            ("2", "panic", "luxon: error: rank 2: panic at"),
            ("0", "error", "luxon: error: injected failure"),
        ] {
            let env = [("LUXON_TEST_FAIL_RANK", rank), ("LUXON_TEST_FAIL", how)];
            let (o, took) = mpirun(3, &args, &env);
            let e = stderr(&o);
            assert!(!o.status.success(), "rank {rank} {how}: the job succeeded");
            assert!(e.contains(says), "rank {rank} {how}: {e}");
            assert!(
                took < Duration::from_secs(10),
                "rank {rank} {how}: took {took:?}"
            );
            assert!(!out.exists());
        }
        let temps = std::fs::read_dir(&dir).unwrap().count();
        assert_eq!(temps, 0, "files left after failed jobs");
    }

    #[test]
    fn more_ranks_than_tiles_or_rows() {
        let dir = temp_dir("mpi-tiny");
        let s = scene();
        for (extra, tag) in [
            (&["--block-size", "64"][..], "one-tile"),
            (&["--decomposition", "scanline-cyclic"][..], "rows"),
        ] {
            let (a, b) = (
                dir.join(format!("{tag}-1.ppm")),
                dir.join(format!("{tag}-4.ppm")),
            );
            let mut args = vec!["render", &s, "--res", "9x3", "-o", a.to_str().unwrap()];
            let o = run(&args);
            assert!(o.status.success(), "{}", stderr(&o));
            args[5] = b.to_str().unwrap();
            args.extend(extra);
            args.push("--stats");
            let (o, _) = mpirun(4, &args, &[]);
            assert!(o.status.success(), "{tag}: {}", stderr(&o));
            assert!(stderr(&o).contains("ranks            4"), "{}", stderr(&o));
            assert_eq!(
                std::fs::read(a).unwrap(),
                std::fs::read(b).unwrap(),
                "{tag}"
            );
        }
    }

    /// The files of a sequence in `d` (name, bytes), without the record directory.
    fn files(d: &Path) -> Vec<(String, Vec<u8>)> {
        let mut v: Vec<_> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap())
            .filter(|e| !e.file_name().to_string_lossy().ends_with(".luxon-frames"))
            .map(|e| {
                let name = e.file_name().to_string_lossy().to_string();
                (name, std::fs::read(e.path()).unwrap())
            })
            .collect();
        v.sort();
        v
    }

    /// `scenes/carousel.ron` (in `dir`) whose camera's `up` passes through zero length at
    /// frame 1, so frame 1 fails and frames 0 and 2 render.
    fn broken_carousel(dir: &Path) -> PathBuf {
        let s = root().join("scenes/carousel.ron");
        let studio = root().join("scenes/include/studio.ron");
        let text = std::fs::read_to_string(&s)
            .unwrap()
            .replace(
                "\"include/studio.ron\"",
                &format!("{:?}", studio.display().to_string()),
            )
            .replace(
                "        camera: (\n",
                "        camera: (\n            up: (keys: [(0, (0, 1, 0)), (2, (0, -1, 0))]),\n",
            );
        let broken = dir.join("broken.ron");
        std::fs::write(&broken, text).unwrap();
        broken
    }

    /// How many frames a run announced as written.
    fn wrote(o: &Output) -> usize {
        stderr(o).matches("luxon: wrote ").count()
    }

    /// Whole frames per rank, groups of two ranks (the last of three alone) and every rank on
    /// every frame all write the files one process writes; rerun under MPI, a finished
    /// sequence renders nothing, and a deleted frame is the only one rendered again.
    #[test]
    fn frame_groups_match_one_process_and_resume() {
        let dir = temp_dir("mpi-frame-groups");
        let s = root().join("scenes/carousel.ron").display().to_string();
        let frames = ["--frames", "0..47", "--step", "12", "--res", "40x30"];
        let one = dir.join("one");
        let pattern = one.join("f%02d.ppm").display().to_string();
        let mut args = vec!["render", &s, "--threads", "1", "-o", &pattern];
        args.extend(frames);
        let o = run(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        let want = files(&one);
        assert_eq!(want.len(), 4);
        let runs: &[(usize, &[&str])] = &[
            (2, &["--frame-groups", "whole"]),
            (
                3,
                &["--frame-groups", "whole", "--decomposition", "pixel-cyclic"],
            ),
            (3, &["--frame-groups", "2"]),
            (
                3,
                &[
                    "--frame-groups",
                    "2",
                    "--parallel",
                    "hybrid",
                    "--threads",
                    "2",
                ],
            ),
            (2, &["--frame-groups", "shared"]),
            (3, &["--frame-groups", "2", "--io", "mpi-io"]),
        ];
        for (i, (ranks, extra)) in runs.iter().enumerate() {
            let out = dir.join(format!("run{i}"));
            let pattern = out.join("f%02d.ppm").display().to_string();
            let mut args = vec!["render", &s, "-o", &pattern];
            args.extend(frames);
            args.extend(*extra);
            let (o, _) = mpirun(*ranks, &args, &[]);
            assert!(o.status.success(), "-np {ranks} {extra:?}: {}", stderr(&o));
            assert_eq!(wrote(&o), 4, "-np {ranks} {extra:?}: {}", stderr(&o));
            assert!(
                files(&out) == want,
                "-np {ranks} {extra:?}: the frames differ"
            );
            if i != 2 {
                continue;
            }
            let (o, _) = mpirun(*ranks, &args, &[]);
            assert!(o.status.success(), "{}", stderr(&o));
            assert!(
                stderr(&o).contains("all 4 frames are done already") && wrote(&o) == 0,
                "{}",
                stderr(&o)
            );
            std::fs::remove_file(out.join("f24.ppm")).unwrap();
            let (o, _) = mpirun(*ranks, &args, &[]);
            assert!(o.status.success(), "{}", stderr(&o));
            assert_eq!(wrote(&o), 1, "{}", stderr(&o));
            assert!(stderr(&o).contains("f24.ppm (frame 24"), "{}", stderr(&o));
            assert!(files(&out) == want, "resumed: the frames differ");
        }
    }

    /// Under whole frames and groups, a frame that fails is reported by its number, the
    /// others are written, and the job ends with status 1 (not an abort).
    #[test]
    fn a_failed_frame_under_frame_groups_is_a_result() {
        let dir = temp_dir("mpi-frame-fail");
        let b = broken_carousel(&dir).display().to_string();
        for (ranks, groups) in [(2, "whole"), (3, "whole"), (3, "2")] {
            let out = dir.join(format!("np{ranks}-{groups}"));
            let pattern = out.join("f%d.ppm").display().to_string();
            let args = [
                "render",
                &b,
                "--frames",
                "0..2",
                "--res",
                "24x18",
                "--frame-groups",
                groups,
                "-o",
                &pattern,
            ];
            let (o, _) = mpirun(ranks, &args, &[]);
            let e = stderr(&o);
            assert_eq!(o.status.code(), Some(1), "{ranks} {groups}: {e}");
            assert!(
                e.contains("luxon: error: frame 1: "),
                "{ranks} {groups}: {e}"
            );
            assert!(
                e.contains("1 of 3 frames failed (1); the other frames are written"),
                "{ranks} {groups}: {e}"
            );
            assert!(!e.contains("MPI_ABORT"), "{ranks} {groups}: {e}");
            let names: Vec<String> = files(&out).into_iter().map(|(n, _)| n).collect();
            assert_eq!(names, ["f0.ppm", "f2.ppm"], "{ranks} {groups}");
        }
    }

    /// How many frames `--stats` says rank `r` of `ranks` rendered (its time line must be there,
    /// with where the rest of its time went). A rank writes its line whole, but `mpirun` may
    /// put it after a part of another rank's output on the same line: found anywhere in a line.
    fn frames_of_rank(e: &str, r: usize, ranks: usize) -> usize {
        let head = format!("luxon: rank {r} of {ranks}: ready after ");
        let line = e
            .lines()
            .find_map(|l| l.find(&head).map(|at| &l[at..]))
            .unwrap_or_else(|| panic!("no time line of rank {r} of {ranks}: {e}"));
        assert!(
            line.contains(", waiting for frames ") && line.contains(", done after "),
            "{line}"
        );
        let counted = line.split(", ").nth(1).unwrap_or_default();
        counted
            .split(" frames rendered in ")
            .next()
            .and_then(|n| n.parse().ok())
            .unwrap_or_else(|| panic!("no frame count: {line}"))
    }

    /// With `--stats`, every rank of a sequence accounts for its time on one line: whole
    /// frames are rendered by one rank each (the counts add up to the frames written), shared
    /// frames by every rank; one process alone prints its line too.
    #[test]
    fn frame_stats_account_for_every_rank() {
        let dir = temp_dir("mpi-frame-clock");
        let s = root().join("scenes/carousel.ron").display().to_string();
        for (ranks, groups) in [(0, "whole"), (3, "whole"), (3, "2"), (2, "shared")] {
            let out = dir.join(format!("np{ranks}-{groups}"));
            let pattern = out.join("f%d.ppm").display().to_string();
            let args = [
                "render",
                &s,
                "--frames",
                "0..5",
                "--res",
                "24x18",
                "--frame-groups",
                groups,
                "--stats",
                "-o",
                &pattern,
            ];
            let o = match ranks {
                0 => run(&args),
                _ => mpirun(ranks, &args, &[]).0,
            };
            let e = stderr(&o);
            assert!(o.status.success(), "{ranks} {groups}: {e}");
            assert_eq!(wrote(&o), 6, "{ranks} {groups}: {e}");
            let (ranks, per_frame) = match (ranks, groups) {
                (0, _) => (1, 1),
                (_, "shared") => (ranks, ranks),
                _ => (ranks, 1),
            };
            let leaders: usize = match groups {
                "2" => [0, 2].iter().map(|&r| frames_of_rank(&e, r, ranks)).sum(),
                _ => (0..ranks).map(|r| frames_of_rank(&e, r, ranks)).sum(),
            };
            assert_eq!(leaders, 6 * per_frame, "{ranks} {groups}: {e}");
            if groups == "2" {
                assert_eq!(
                    frames_of_rank(&e, 1, ranks),
                    frames_of_rank(&e, 0, ranks),
                    "{e}"
                );
            }
        }
    }

    /// Ranks that cannot see the directory rank 0 writes the frame records to are refused
    /// before any frame: here the two ranks start in different directories and the output
    /// name is relative.
    #[test]
    fn frame_groups_need_a_shared_output_directory() {
        ensure_plugins();
        let dir = temp_dir("mpi-frame-dir");
        let (a, b) = (dir.join("a"), dir.join("b"));
        std::fs::create_dir_all(&a).unwrap();
        std::fs::create_dir_all(&b).unwrap();
        let s = root().join("scenes/carousel.ron").display().to_string();
        let exe = env!("CARGO_BIN_EXE_luxon");
        let luxon_args = [
            exe,
            "render",
            &s,
            "--frames",
            "0..1",
            "--res",
            "16x12",
            "--frame-groups",
            "whole",
            "-o",
            "out/f%d.ppm",
        ];
        let mut cmd = Command::new("mpirun");
        cmd.env("OMPI_ALLOW_RUN_AS_ROOT", "1")
            .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
            .args(["--oversubscribe", "--bind-to", "none", "--timeout"])
            .arg(DEADLINE.as_secs().to_string())
            .args(["-np", "1", "-wdir", a.to_str().unwrap()])
            .args(luxon_args)
            .args([":", "-np", "1", "-wdir", b.to_str().unwrap()])
            .args(luxon_args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        let (o, _) = run_with_deadline(&mut cmd, DEADLINE + Duration::from_secs(15), "mpirun");
        let e = stderr(&o);
        assert!(!o.status.success(), "{e}");
        assert!(
            e.contains("rank 1: the output directory is not shared between ranks")
                && e.contains("out/.f%d.ppm.luxon-frames"),
            "{e}"
        );
        assert!(!a.join("out/f0.ppm").exists() && !b.join("out").exists());
    }

    /// An animated scene's frames under 2 and 3 ranks equal one process's, file for file;
    /// a frame that fails (its camera degenerates) is skipped by every rank, the others
    /// written, and the job ends with status 1.
    #[test]
    fn animation_frames_match_one_process() {
        let dir = temp_dir("mpi-frames");
        let s = root().join("scenes/carousel.ron").display().to_string();
        let frames = ["--frames", "0..47", "--step", "23", "--res", "48x36"];
        let one = dir.join("one");
        let pattern = one.join("f%02d.ppm").display().to_string();
        let mut args = vec!["render", &s, "--threads", "1", "-o", &pattern];
        args.extend(frames);
        let o = run(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        let want = files(&one);
        assert_eq!(want.len(), 3);
        for (ranks, extra) in [(2, &["--parallel", "mpi"][..]), (3, &[][..])] {
            let out = dir.join(format!("np{ranks}"));
            let pattern = out.join("f%02d.ppm").display().to_string();
            let mut args = vec!["render", &s, "-o", &pattern];
            args.extend(frames);
            args.extend(extra);
            let (o, _) = mpirun(ranks, &args, &[]);
            assert!(o.status.success(), "-np {ranks}: {}", stderr(&o));
            assert!(files(&out) == want, "-np {ranks}: the frames differ");
            // Run again: every frame is done, none is rendered.
            let (o, _) = mpirun(ranks, &args, &[]);
            assert!(o.status.success(), "-np {ranks}: {}", stderr(&o));
            assert!(
                stderr(&o).contains("all 3 frames are done already")
                    && !stderr(&o).contains("luxon: wrote"),
                "-np {ranks}: {}",
                stderr(&o)
            );
        }
        let broken = broken_carousel(&dir);
        let out = dir.join("broken");
        let pattern = out.join("f%d.ppm").display().to_string();
        let b = broken.display().to_string();
        let args = [
            "render", &b, "--frames", "0..2", "--res", "24x18", "-o", &pattern,
        ];
        let (o, _) = mpirun(2, &args, &[]);
        assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
        assert!(stderr(&o).contains("frames failed (1)"), "{}", stderr(&o));
        let names: Vec<String> = files(&out).into_iter().map(|(n, _)| n).collect();
        assert_eq!(names, ["f0.ppm", "f2.ppm"]);
    }

    /// Each plugin instance's NaN results are counted on every rank and added up on rank 0:
    /// the warning naming the texture gives the same count as a single process.
    #[test]
    fn nan_counts_of_every_rank_reach_the_warning() {
        let dir = temp_dir("mpi-nan");
        install_plugin(&dir, "testplug_nan", "luxon_nan");
        let scene = dir.join("nan.ron");
        std::fs::write(
            &scene,
            format!(
                "Scene(plugin_path: [{:?}], camera: (position: (0, 0, -5), look_at: (0, 0, 0)), \
                 lights: [Directional(direction: (0, 0, 1))], \
                 textures: {{ \"half\": (plugin: \"nan_texture\") }}, \
                 materials: {{ \"m\": (texture: \"half\") }}, \
                 objects: [(plugin: \"sphere\", params: (center: (0, 0, 0), radius: 1.5), \
                 material: \"m\")])",
                dir.display().to_string()
            ),
        )
        .unwrap();
        let out = dir.join("nan.png");
        let s = scene.display().to_string();
        let args = [
            "render",
            &s,
            "--res",
            "24x24",
            "--parallel",
            "mpi",
            "--decomposition",
            "pixel-cyclic",
            "-o",
            out.to_str().unwrap(),
        ];
        let warning = |o: &Output| {
            let e = stderr(o);
            assert!(o.status.success(), "{e}");
            e.lines()
                .find(|l| l.contains("texture `half` (plugin `nan_texture`) gave NaN"))
                .unwrap_or_else(|| panic!("no warning naming the texture in {e}"))
                .to_string()
        };
        let one = warning(&luxon().args(&args[..4]).args(&args[8..]).output().unwrap());
        let (o, _) = mpirun(2, &args, &[]);
        assert_eq!(warning(&o), one);
    }
}
