//! A sequence's frames over groups of MPI ranks (`render: (parallel: (frames: Whole |
//! Groups(n)))`, `--frame-groups`): consecutive ranks form groups of `n`; each group's leader
//! takes frames from rank 0's queue ([`FrameQueue`]), the group renders each frame as one image
//! is rendered (its pixels shared by the scene's decomposition, on the group's own
//! communicator), and the leader writes it and reports it (with its request for the next
//! frame). Rank 0 keeps the frame records, as with one group, so a resumed run renders only the
//! frames missing.

use super::frame_clock::FrameClock;
use super::job::Job;
use super::sequence::{Each, Tally, NO_FRAME};
use luxon::api::Scene;
use luxon::output::frames::FrameNames;
use luxon::output::manifest::Manifest;
use luxon::schedule::cluster::Cluster;
use luxon::schedule::frames::FrameQueue;
use luxon::schedule::wire::FrameResult;
use luxon::Error;
use std::sync::{Mutex, PoisonError};
use std::time::Instant;

/// Collective: whether every rank sees the frame records rank 0 created beside the first
/// output (group leaders write frames there). `Err(None)`: another rank reports it.
pub(super) fn check_shared_dir(names: &FrameNames, job: &Job) -> Result<(), Option<Error>> {
    let seen = match names.first() {
        Some(first) => {
            let dir = Manifest::beside(first).dir().to_path_buf();
            match dir.is_dir() {
                true => Ok(1),
                false => Err(Error::Usage(format!(
                    "the output directory is not shared between ranks: {} cannot see {} \
                     (rank 0 created it); frame groups write frames from every node, so \
                     the outputs must be on a file system all nodes share",
                    host(),
                    dir.display()
                ))),
            }
        }
        None => Ok(1),
    };
    job.agree(seen).map(|_| ())
}

/// This node's name, for messages.
fn host() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .map(|h| h.trim().to_string())
        .ok()
        .filter(|h| !h.is_empty())
        .map_or_else(|| "this node".into(), |h| format!("node {h}"))
}

/// Renders the frames over groups of `n` ranks of `world`; rank 0 deals them and returns the
/// tally (other ranks `None`).
pub(super) fn run(
    each: &Each,
    scene: &mut Scene,
    world: &Cluster,
    n: usize,
    tally: Option<Tally>,
    clock: &mut FrameClock,
) -> Result<Option<Tally>, Error> {
    let queue = FrameQueue::new(world);
    let group = match n {
        1 => Job::Local,
        _ => Job::Mpi(world.split(n)),
    };
    let result = match tally {
        Some(tally) => {
            let groups = world.size().div_ceil(n);
            let tally = Mutex::new(tally);
            let lock = || tally.lock().unwrap_or_else(PoisonError::into_inner);
            let next = || lock().next();
            let report = |r: FrameResult| lock().report(r);
            // Rank 0's own frames are recorded by the dealer thread (recording syncs a file),
            // so that rank 0 goes on to its next frame at once.
            let own = Mutex::new(Vec::new());
            let take_own =
                || std::mem::take(&mut *own.lock().unwrap_or_else(PoisonError::into_inner));
            let record_own = || take_own().into_iter().for_each(report);
            let next_own = |done: Option<FrameResult>| {
                let k = next();
                if let Some(r) = done {
                    own.lock().unwrap_or_else(PoisonError::into_inner).push(r);
                }
                k
            };
            std::thread::scope(|sc| {
                sc.spawn(|| queue.deal(groups - 1, &next, &report, &record_own));
                frames(each, scene, &group, next_own, clock);
            });
            record_own();
            Some(tally.into_inner().unwrap_or_else(PoisonError::into_inner))
        }
        None => {
            // A frame's report goes with the request for the next one.
            frames(
                each,
                scene,
                &group,
                |done| queue.request(done.as_ref()),
                clock,
            );
            None
        }
    };
    // The group's communicator is freed before the job's.
    drop(group);
    Ok(result)
}

/// One group's loop: its leader's `next(done)` reports how the group's previous frame ended
/// (none before the first) and gives the next frame, which goes to every member, which renders
/// it.
fn frames(
    each: &Each,
    scene: &mut Scene,
    group: &Job,
    next: impl Fn(Option<FrameResult>) -> Option<u32>,
    clock: &mut FrameClock,
) {
    let mut done = None;
    loop {
        let k = clock.wait(|| {
            let k = match group.rank() {
                0 => next(done.take()).map_or(NO_FRAME, u64::from),
                _ => NO_FRAME,
            };
            group.root_value(k)
        });
        if k == NO_FRAME {
            return;
        }
        let k = k as u32;
        let t = Instant::now();
        done = clock
            .render(|| each.frame(k, scene, group))
            .map(|outcome| FrameResult {
                frame: k,
                outcome,
                seconds: t.elapsed().as_secs_f64(),
            });
    }
}
