//! The library with MPI owned by its caller (feature `mpi`; OpenMPI): a simulation-like program
//! of 4 ranks splits its world in two; ranks 0–1 render through `luxon::api` over their half
//! while ranks 2–3 run collectives of their own, then everyone meets in a world barrier. The
//! image must equal one process's, a failing rank must be an error value on both rendering
//! ranks (the job still ends well), and nothing may hang: every mpirun has a deadline.
//!
//! The ranks are this test binary itself: the test starts `mpirun ... <this binary> --exact
//! <the test>` with `LUXON_GUEST_RANK` set, and in those processes the same test function plays
//! one rank (MPI can be initialised once per process, so never in the test process itself).

mod common;

#[cfg(feature = "mpi")]
mod with_mpi {
    use super::common::*;
    use luxon::api::{
        Color, Context, ContextOptions, Plane, Renderer, RendererOptions, Scene, Target,
    };
    use luxon::Error;
    use luxon_formats::Decomposition;
    use mpi::collective::SystemOperation;
    use mpi::topology::{Color as Split, SimpleCommunicator};
    use mpi::traits::*;
    use std::path::{Path, PathBuf};
    use std::process::{Command, Output, Stdio};
    use std::time::Duration;

    const DEADLINE: Duration = Duration::from_secs(90);
    /// Set in the processes mpirun starts: play one rank.
    const ROLE: &str = "LUXON_GUEST_RANK";
    /// Where rank 0 writes its images and every rendering rank its error.
    const OUT: &str = "LUXON_GUEST_OUT";
    const SIZE: (u32, u32) = (97, 61);
    /// Each render of the run: the scene's own decomposition (dynamic) and two static ones.
    const DECOMPOSITIONS: [Decomposition; 3] = [
        Decomposition::Dynamic,
        Decomposition::ScanlineCyclic,
        Decomposition::BlockCyclic,
    ];

    fn scene_desc(how: Decomposition) -> luxon_formats::SceneDesc {
        let path = root().join("scenes/spheres.ron");
        let mut desc = luxon_formats::load(&path).unwrap();
        desc.render.parallel.decomposition = how;
        desc.render.parallel.tile_size = 16;
        desc
    }

    /// RGBA f32 of `scene` rendered through `renderer` (rank 0, or one process), as bytes.
    fn render_f32(renderer: &Renderer, scene: &mut Scene) -> Result<Vec<u8>, Error> {
        let (w, h) = SIZE;
        let mut px = vec![[0f32; 4]; (w * h) as usize];
        let target = Target {
            width: w,
            height: h,
            color: Color::Rgba32fLinear(Plane::new(&mut px, w as usize)),
            depth: None,
        };
        renderer.render(scene, target)?;
        Ok(px.iter().flatten().flat_map(|v| v.to_ne_bytes()).collect())
    }

    /// The image of rank 0 (other ranks: a target without planes).
    fn render_rank(
        renderer: &Renderer,
        scene: &mut Scene,
        rank: usize,
    ) -> Result<Option<Vec<u8>>, Error> {
        if rank == 0 {
            return render_f32(renderer, scene).map(Some);
        }
        let target = Target {
            width: SIZE.0,
            height: SIZE.1,
            color: Color::None,
            depth: None,
        };
        renderer.render(scene, target).map(|_| None)
    }

    /// One rendering rank: a renderer over `half`, three renders (one per decomposition, the
    /// same renderer: no message of one render may reach the next), then the thread rule.
    fn render_half(half: &SimpleCommunicator, out: &Path, failing: bool) -> Renderer {
        let rank = half.rank() as usize;
        let panicking = std::env::var("LUXON_TEST_FAIL").is_ok_and(|m| m == "panic");
        let ctx = Context::new(ContextOptions {
            threads: 2,
            ..Default::default()
        })
        .unwrap();
        let renderer = Renderer::with_communicator(&ctx, RendererOptions::default(), half).unwrap();
        assert_eq!(renderer.communicator(), Some((rank, 2)));
        for how in DECOMPOSITIONS {
            let mut scene = Scene::from_desc(&ctx, scene_desc(how)).unwrap();
            match render_rank(&renderer, &mut scene, rank) {
                Ok(image) if !failing => {
                    if let Some(bytes) = image {
                        std::fs::write(out.join(format!("{how:?}.f32")), bytes).unwrap();
                    }
                }
                // An injected panic needs a tile on rank 1 (see the test).
                Ok(_) if failing && panicking && how == Decomposition::Dynamic => {}
                Err(e) if failing => {
                    std::fs::write(out.join(format!("error-{rank}-{how:?}.txt")), e.to_string())
                        .unwrap();
                }
                other => panic!(
                    "rank {rank} {how:?}: {:?}",
                    other.map(|i| i.map(|b| b.len()))
                ),
            }
        }
        // MPI was initialised with MPI_THREAD_FUNNELED: another thread may not render (a
        // local error on each rank, before any MPI call).
        let mut scene = Scene::from_desc(&ctx, scene_desc(Decomposition::Dynamic)).unwrap();
        let e = std::thread::scope(|s| {
            s.spawn(|| render_rank(&renderer, &mut scene, rank))
                .join()
                .unwrap()
        })
        .unwrap_err();
        assert!(matches!(e, Error::Mpi(_)), "{e:?}");
        assert!(e.to_string().contains("MPI_THREAD_FUNNELED"), "{e}");
        renderer
    }

    /// One rank of the job (in a process mpirun started).
    fn play_rank() {
        let out = PathBuf::from(std::env::var(OUT).unwrap());
        let failing = std::env::var("LUXON_TEST_FAIL_RANK").is_ok();
        let (universe, _) = mpi::initialize_with_threading(mpi::Threading::Funneled).unwrap();
        let world = universe.world();
        let rank = world.rank();
        assert_eq!(world.size(), 4);
        let half = world.split_by_color(Split::with_value(rank / 2)).unwrap();
        let mut renderer = None;
        if rank < 2 {
            renderer = Some(render_half(&half, &out, failing));
        } else {
            // Collectives of the other half, meanwhile: they must neither wait for the
            // renderers nor see their messages.
            for i in 0..2000u64 {
                let mut sum = 0u64;
                half.all_reduce_into(&(i + rank as u64), &mut sum, SystemOperation::sum());
                assert_eq!(sum, 2 * i + 5);
            }
            std::fs::write(out.join(format!("collectives-{rank}.txt")), "2000").unwrap();
        }
        world.barrier();
        drop(half);
        drop(universe);
        // MPI is finalised: a communicator is refused with a message, and the renderer holding
        // a duplicate can still be dropped (it must not call MPI).
        if let Some(r) = renderer {
            let e = r.set_fortran_communicator(0).unwrap_err();
            assert!(e.to_string().contains("MPI has been finalised"), "{e}");
            drop(r);
        }
        std::fs::write(out.join(format!("finished-{rank}.txt")), "").unwrap();
    }

    /// Runs the 4-rank job of the test `name` (this binary, `--exact`), killed after the
    /// deadline (mpirun's own `--timeout` too, so a hung job cannot outlive the test).
    fn mpirun(name: &str, out: &Path, env: &[(&str, &str)]) -> Output {
        ensure_plugins();
        let mut cmd = Command::new("mpirun");
        cmd.env("OMPI_ALLOW_RUN_AS_ROOT", "1")
            .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
            .env(ROLE, "1")
            .env(OUT, out)
            .args(["--oversubscribe", "--bind-to", "none", "--timeout"])
            .arg(DEADLINE.as_secs().to_string())
            .args(["-x", ROLE, "-x", OUT]);
        for (k, v) in env {
            cmd.env(k, v).args(["-x", k]);
        }
        cmd.args(["-np", "4"])
            .arg(std::env::current_exe().unwrap())
            .args(["--exact", name, "--nocapture", "--test-threads=1"])
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        run_with_deadline(
            &mut cmd,
            DEADLINE + Duration::from_secs(15),
            &format!("mpirun -np 4 {name}"),
        )
        .0
    }

    fn report(o: &Output) -> String {
        format!(
            "status {:?}\nstdout:\n{}\nstderr:\n{}",
            o.status,
            String::from_utf8_lossy(&o.stdout),
            stderr(o)
        )
    }

    /// Every rank got through the collectives and the final barrier, and finished.
    fn assert_every_rank_finished(out: &Path, o: &Output) {
        assert!(o.status.success(), "{}", report(o));
        for rank in 0..4 {
            assert!(
                out.join(format!("finished-{rank}.txt")).exists(),
                "rank {rank}: {}",
                report(o)
            );
        }
        for rank in 2..4 {
            let n = std::fs::read_to_string(out.join(format!("collectives-{rank}.txt"))).unwrap();
            assert_eq!(n, "2000");
        }
    }

    #[test]
    fn a_sub_communicator_renders_the_image_of_one_process() {
        if std::env::var_os(ROLE).is_some() {
            return play_rank();
        }
        let out = temp_dir("mpi-guest");
        let o = mpirun(
            "with_mpi::a_sub_communicator_renders_the_image_of_one_process",
            &out,
            &[],
        );
        assert_every_rank_finished(&out, &o);
        let ctx = Context::new(ContextOptions {
            threads: 1,
            ..Default::default()
        })
        .unwrap();
        let alone = Renderer::new(&ctx, RendererOptions::default()).unwrap();
        for how in DECOMPOSITIONS {
            let mut scene = Scene::from_desc(&ctx, scene_desc(how)).unwrap();
            let want = render_f32(&alone, &mut scene).unwrap();
            let got = std::fs::read(out.join(format!("{how:?}.f32"))).unwrap();
            assert!(got == want, "{how:?}: the image differs from one process's");
        }
        let _ = std::fs::remove_dir_all(&out);
    }

    #[test]
    fn a_failing_rank_is_an_error_on_every_rendering_rank() {
        if std::env::var_os(ROLE).is_some() {
            return play_rank();
        }
        for mode in ["error", "panic"] {
            let out = temp_dir(&format!("mpi-guest-fail-{mode}"));
            let o = mpirun(
                "with_mpi::a_failing_rank_is_an_error_on_every_rendering_rank",
                &out,
                &[("LUXON_TEST_FAIL_RANK", "1"), ("LUXON_TEST_FAIL", mode)],
            );
            assert_every_rank_finished(&out, &o);
            let says = match mode {
                "error" => "rank 1: injected failure (LUXON_TEST_FAIL_RANK)",
                _ => {
                    "rank 1: internal error (a bug in Luxon; please report it): a render \
                      thread panicked: injected panic (LUXON_TEST_FAIL_RANK)"
                }
            };
            for rank in 0..2 {
                for how in DECOMPOSITIONS {
                    // An injected panic needs a tile on rank 1, which the dynamic
                    // decomposition may not give it (an injected error is raised anyway).
                    if mode == "panic" && how == Decomposition::Dynamic {
                        continue;
                    }
                    let file = out.join(format!("error-{rank}-{how:?}.txt"));
                    let e = std::fs::read_to_string(&file).unwrap_or_else(|_| {
                        panic!("{mode}: no {}: {}", file.display(), report(&o))
                    });
                    assert_eq!(e, says, "{mode} rank {rank} {how:?}");
                }
            }
            let _ = std::fs::remove_dir_all(&out);
        }
    }

    /// Without MPI initialised (this test process never initialises it), a communicator is
    /// refused with a message.
    #[test]
    fn a_communicator_before_mpi_init_is_refused() {
        let ctx = Context::new(ContextOptions {
            threads: 1,
            ..Default::default()
        })
        .unwrap();
        let r = Renderer::new(&ctx, RendererOptions::default()).unwrap();
        let e = r.set_fortran_communicator(0).unwrap_err();
        assert!(matches!(e, Error::Mpi(_)), "{e:?}");
        assert!(e.to_string().starts_with("MPI is not initialised"), "{e}");
        assert_eq!(r.communicator(), None);
    }
}
