//! The in-situ C example `examples/insitu/heat.c` (a 3-D heat simulation that renders its field
//! as a volume through the C API) compiled with the system `cc` as C99 with every warning an
//! error, run at a small size: its frames decode, the heaters show (hot colours over a dark
//! background), the heat spreads from frame to frame (the field is marked modified and read
//! again), and two runs write the same bytes. With MPI built, the same file compiled with
//! `mpicc -DLUXON_EXAMPLE_MPI` runs as 4 ranks with `--split` (2 render in a sub-communicator,
//! 2 run collectives of their own) and writes the one-process frames, bit for bit.

mod common;

use common::{ensure_built, profile_dir, report, root, temp_dir};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const ARGS: [&str; 6] = ["--size", "24", "--steps", "20", "--every", "5"];

/// Compiles heat.c with `compiler` (`cc` or `mpicc`) and `defines` into `dir/heat-COMPILER`,
/// or `None` when there is no such compiler.
fn compile(compiler: &str, defines: &[&str], dir: &Path) -> Option<PathBuf> {
    let runs = Command::new(compiler).arg("--version").output();
    if !runs.is_ok_and(|o| o.status.success()) {
        return None;
    }
    ensure_built();
    let lib = profile_dir();
    let exe = dir.join(format!("heat-{compiler}"));
    let o = Command::new(compiler)
        .args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-O2"])
        .args(defines)
        .arg("-I")
        .arg(root().join("core/capi/include"))
        .arg(root().join("examples/insitu/heat.c"))
        .arg("-o")
        .arg(&exe)
        .arg("-L")
        .arg(&lib)
        .arg(format!("-Wl,-rpath,{}", lib.display()))
        .args(["-lluxon", "-lm"])
        .output()
        .unwrap_or_else(|e| panic!("cannot run {compiler}: {e}"));
    assert!(o.status.success(), "{compiler}: {}", report(&o));
    Some(exe)
}

/// Runs the compiled example into `out` (plugins from beside libluxon.so).
fn run_heat(exe: &Path, out: &Path) -> Output {
    std::fs::create_dir_all(out).unwrap();
    let o = Command::new(exe)
        .args(ARGS)
        .arg("--out")
        .arg(out)
        .env_remove("LUXON_PLUGIN_PATH")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", report(&o));
    o
}

fn frames(out: &Path) -> Vec<Vec<u8>> {
    let names: Vec<String> = (0..4).map(|k| format!("frame{k:04}.png")).collect();
    let mut found: Vec<String> = std::fs::read_dir(out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    found.sort();
    assert_eq!(found, names, "the frames written to {}", out.display());
    names
        .iter()
        .map(|n| std::fs::read(out.join(n)).unwrap())
        .collect()
}

#[test]
fn the_heat_example_renders_its_field_in_situ() {
    let dir = temp_dir("heat");
    let Some(exe) = compile("cc", &[], &dir) else {
        println!("note: no C compiler (cc) found; skipping the in-situ C example");
        return;
    };
    let o = run_heat(&exe, &dir.join("a"));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("24^3 grid, 20 steps, 4 frames: sim"),
        "{}",
        report(&o)
    );
    let first = frames(&dir.join("a"));
    let mut heat = Vec::new();
    for (k, png) in first.iter().enumerate() {
        let img = image::load_from_memory(png)
            .unwrap_or_else(|e| panic!("frame {k}: {e}"))
            .to_rgb8();
        assert_eq!(img.dimensions(), (320, 240));
        // The heaters: red to yellow pixels; the corners are the dark background.
        let hot = img
            .pixels()
            .filter(|p| p.0[0] > 120 && p.0[0] > p.0[2].saturating_add(60))
            .count();
        assert!(hot > 300, "frame {k}: {hot} hot pixels");
        assert!(img.get_pixel(0, 0).0.iter().all(|&c| c < 70), "frame {k}");
        heat.push(img.pixels().map(|p| u64::from(p.0[0])).sum::<u64>());
    }
    // The heat spreads: every frame is redder than the one before.
    assert!(
        heat.windows(2).all(|w| w[1] > w[0]),
        "red per frame: {heat:?}"
    );

    run_heat(&exe, &dir.join("b"));
    assert!(first == frames(&dir.join("b")), "two runs differ");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_bad_argument_is_refused_with_a_message() {
    let dir = temp_dir("heat-args");
    let Some(exe) = compile("cc", &[], &dir) else {
        println!("note: no C compiler (cc) found; skipping the in-situ C example");
        return;
    };
    let o = Command::new(&exe).args(["--split"]).output().unwrap();
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("--split needs the MPI build"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[cfg(feature = "mpi")]
#[test]
fn the_heat_example_under_mpirun_with_a_split_world_renders_the_same_frames() {
    use std::process::Stdio;
    use std::time::{Duration, Instant};
    const DEADLINE: Duration = Duration::from_secs(120);

    let dir = temp_dir("heat-mpi");
    let serial = dir.join("serial");
    let exe = compile("cc", &[], &dir).expect("no C compiler (cc)");
    run_heat(&exe, &serial);
    let want = frames(&serial);

    let parallel = dir.join("split");
    std::fs::create_dir_all(&parallel).unwrap();
    let exe = compile("mpicc", &["-DLUXON_EXAMPLE_MPI"], &dir)
        .expect("cannot run mpicc (install OpenMPI's development files)");
    let mut cmd = Command::new("mpirun");
    cmd.env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .env_remove("LUXON_PLUGIN_PATH")
        .args(["--oversubscribe", "--bind-to", "none", "--timeout"])
        .arg(DEADLINE.as_secs().to_string())
        .args(["-np", "4"])
        .arg(&exe)
        .args(ARGS)
        .args(["--split", "--quiet", "--out"])
        .arg(&parallel)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let start = Instant::now();
    let mut child = cmd.spawn().expect("cannot run mpirun (install OpenMPI)");
    while child.try_wait().expect("mpirun").is_none() {
        if start.elapsed() > DEADLINE + Duration::from_secs(15) {
            let _ = child.kill();
            panic!("mpirun -np 4 heat --split hung");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let o = child.wait_with_output().expect("mpirun output");
    assert!(o.status.success(), "{}", report(&o));
    assert!(
        frames(&parallel) == want,
        "the split job's frames differ from one process's"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
