//! MPI owned by the caller through the C API. Without the `mpi` feature the call is refused as
//! unsupported, naming the feature. With it, a C program compiled with `mpicc`
//! (`tests/c/mpi_split.c`, through `include/luxon_mpi.h`) runs as 4 ranks: two render
//! `scenes/spheres.ron` over their half of a split world while the other two run collectives
//! of their own; the image equals the Rust API's render in one process, bit for bit, and a
//! failing rank is an error on both rendering ranks while the job still ends well. Every
//! mpirun has a deadline.

mod common;

use common::capi::*;

/// In this test process MPI is never initialised: with MPI built in, the communicator is
/// refused for that; without it, as unsupported. A null renderer is an error either way.
#[test]
fn a_communicator_is_refused_without_mpi_initialised_or_built_in() {
    let api = capi();
    let r = renderer(context());
    // SAFETY: handles are plain numbers.
    unsafe {
        let s = (api.luxon_renderer_set_mpi_comm_f)(Handle::default(), 0);
        expect(s, INVALID_HANDLE, "the luxon_renderer is null");
        assert_eq!((api.luxon_has_mpi)(), cfg!(feature = "mpi"));
        let s = (api.luxon_renderer_set_mpi_comm_f)(r, 0);
        if cfg!(feature = "mpi") {
            expect(s, MPI, "MPI is not initialised: call MPI_Init_thread");
        } else {
            expect(s, UNSUPPORTED, "this libluxon was built without MPI");
            assert!(
                last_error().contains("cargo feature `mpi`"),
                "{}",
                last_error()
            );
        }
        expect((api.luxon_renderer_release)(r), OK, "");
    }
}

#[cfg(feature = "mpi")]
mod with_mpi {
    use super::common::{
        bits, ensure_built, profile_dir, render_f32, report, root, rust_api, temp_dir,
    };
    use std::path::{Path, PathBuf};
    use std::process::{Command, Output, Stdio};
    use std::time::{Duration, Instant};

    const DEADLINE: Duration = Duration::from_secs(90);
    const W: u32 = 97;
    const H: u32 = 61;

    /// `tests/c/mpi_split.c` compiled with mpicc against libluxon.so (with MPI).
    fn compile(dir: &Path) -> PathBuf {
        ensure_built();
        let lib = profile_dir();
        let here = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
        let exe = dir.join("mpi_split");
        let o = Command::new("mpicc")
            .args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-I"])
            .arg(here.join("include"))
            .arg(here.join("tests/c/mpi_split.c"))
            .arg("-o")
            .arg(&exe)
            .arg("-L")
            .arg(&lib)
            .arg(format!("-Wl,-rpath,{}", lib.display()))
            .arg("-lluxon")
            .output()
            .expect("cannot run mpicc (install OpenMPI's development files)");
        assert!(o.status.success(), "mpicc: {}", report(&o));
        exe
    }

    /// `mpirun -np 4 exe SCENE out`, killed after the deadline (mpirun's own `--timeout` too).
    fn mpirun(exe: &Path, out: &Path, env: &[(&str, &str)]) -> Output {
        let mut cmd = Command::new("mpirun");
        cmd.env("OMPI_ALLOW_RUN_AS_ROOT", "1")
            .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
            .args(["--oversubscribe", "--bind-to", "none", "--timeout"])
            .arg(DEADLINE.as_secs().to_string());
        for (k, v) in env {
            cmd.env(k, v).args(["-x", k]);
        }
        cmd.args(["-np", "4"])
            .arg(exe)
            .arg(root().join("scenes/spheres.ron"))
            .arg(out)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        let start = Instant::now();
        let mut child = cmd.spawn().expect("cannot run mpirun (install OpenMPI)");
        while child.try_wait().expect("mpirun").is_none() {
            if start.elapsed() > DEADLINE + Duration::from_secs(15) {
                let _ = child.kill();
                panic!("mpirun -np 4 {} hung", exe.display());
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        let o = child.wait_with_output().expect("mpirun output");
        assert!(o.status.success(), "{}", report(&o));
        for rank in 0..4 {
            let done = out.join(format!("finished-{rank}.txt"));
            assert!(done.exists(), "rank {rank} did not finish: {}", report(&o));
        }
        o
    }

    #[test]
    fn a_sub_communicator_renders_what_one_process_renders() {
        let dir = temp_dir("mpi-split");
        let exe = compile(&dir);
        let out = dir.join("ok");
        std::fs::create_dir_all(&out).unwrap();
        mpirun(&exe, &out, &[]);
        let got: Vec<u32> = std::fs::read(out.join("image.f32"))
            .unwrap()
            .chunks_exact(4)
            .map(|b| u32::from_ne_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        let (ctx, renderer) = rust_api();
        let mut scene = luxon_core::api::Scene::load(&ctx, &root().join("scenes/spheres.ron"))
            .unwrap_or_else(|e| panic!("{e}"));
        let want = render_f32(&renderer, &mut scene, W, H);
        assert!(got == bits(&want), "the image differs from one process's");

        let out = dir.join("fail");
        std::fs::create_dir_all(&out).unwrap();
        mpirun(&exe, &out, &[("LUXON_TEST_FAIL_RANK", "1")]);
        for rank in 0..2 {
            let e = std::fs::read_to_string(out.join(format!("error-{rank}.txt"))).unwrap();
            assert_eq!(
                e, "rank 1: injected failure (LUXON_TEST_FAIL_RANK)",
                "rank {rank}"
            );
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}
