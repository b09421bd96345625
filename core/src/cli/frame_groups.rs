//! A sequence's frames over groups of MPI ranks (`render: (parallel: (frames: Whole |
//! Groups(n)))`, `--frame-groups`): consecutive ranks form groups of `n`; each group's leader
//! takes frames from rank 0's queue ([`FrameQueue`]), the group renders each frame as one image
//! is rendered (its pixels shared by the scene's decomposition, on the group's own
//! communicator), and the leader writes it and reports it. Rank 0 keeps the frame records, as
//! with one group, so a resumed run renders only the frames missing.

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
) -> Result<Option<Tally>, Error> {
    let queue = FrameQueue::new(world);
    let group = match n {
        1 => Job::Local,
        _ => Job::Mpi(world.split(n)),
    };
    let leader = group.rank() == 0;
    let result = match tally {
        Some(tally) => {
            let groups = world.size().div_ceil(n);
            let tally = Mutex::new(tally);
            let lock = || tally.lock().unwrap_or_else(PoisonError::into_inner);
            let next = || lock().next();
            let report = |r: FrameResult| lock().report(r);
            std::thread::scope(|sc| {
                sc.spawn(|| queue.deal(groups - 1, &next, &report));
                frames(each, scene, &group, next, report);
            });
            Some(tally.into_inner().unwrap_or_else(PoisonError::into_inner))
        }
        None => {
            let next = || match leader {
                true => queue.request(),
                false => None,
            };
            frames(each, scene, &group, next, |r| queue.report(&r));
            None
        }
    };
    // The group's communicator is freed before the job's.
    drop(group);
    Ok(result)
}

/// One group's loop: its leader's `next` frame goes to every member, which renders it; the
/// leader `report`s how it ended.
fn frames(
    each: &Each,
    scene: &mut Scene,
    group: &Job,
    next: impl Fn() -> Option<u32>,
    report: impl Fn(FrameResult),
) {
    loop {
        let k = match group.rank() {
            0 => next().map_or(NO_FRAME, u64::from),
            _ => NO_FRAME,
        };
        let k = group.root_value(k);
        if k == NO_FRAME {
            return;
        }
        let k = k as u32;
        let t = Instant::now();
        if let Some(outcome) = each.frame(k, scene, group) {
            report(FrameResult {
                frame: k,
                outcome,
                seconds: t.elapsed().as_secs_f64(),
            });
        }
    }
}
