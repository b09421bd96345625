//! The frames of a sequence dealt to groups of MPI ranks (feature `mpi`): rank 0 keeps the queue
//! and answers each group leader's request with the next frame (or none left). A request
//! carries how the leader's previous frame ended (a failed frame is such a report, not an
//! abort), and rank 0 answers it before it records that frame: recording writes and syncs a
//! file, which the leader need not wait for. The messages travel on a duplicate of the job's
//! communicator, so they never meet the tile protocol of a group rendering meanwhile.
//!
//! Rank 0 also renders frames (as a group leader): it deals from a thread of its own that polls
//! and sleeps between polls (OpenMPI's blocking calls spin and would take a core from the
//! render threads), so dealing never waits for a frame to finish.

use super::cluster::Cluster;
use super::mailbox::{bytes_of, word, POLL};
use super::wire::{decode_frame_result, encode_frame_result, FrameResult};
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;

const TAG_FRAME_REQUEST: i32 = 21;
const TAG_FRAME: i32 = 22;
/// The answer when no frame is left.
const NO_FRAME: u64 = u64::MAX;

/// The job's frame queue, as seen from one rank.
pub struct FrameQueue {
    comm: SimpleCommunicator,
}

// SAFETY: the queue holds an MPI communicator handle, a plain value any thread may pass to MPI:
// the command's MPI runs at `MPI_THREAD_MULTIPLE` (`Cluster::init` refuses less). rsmpi marks
// it !Send only because the handle is a raw pointer in some MPI libraries. Each queue is used
// by one thread at a time (it is moved, never shared).
unsafe impl Send for FrameQueue {}

impl FrameQueue {
    /// Collective over every rank of `cluster`.
    pub fn new(cluster: &Cluster) -> FrameQueue {
        FrameQueue {
            comm: cluster.duplicate(),
        }
    }

    /// Rank 0: answers the leaders of the other groups, `leaders` of them, until each has been
    /// told that no frame is left (so their reports are in too: the last one came with the last
    /// request). `next` gives the next frame to render; `report` takes each reported frame.
    /// Both may be shared with rank 0's own leader (through a lock). `idle` runs between polls
    /// (rank 0 records its own frames there).
    pub fn deal(
        self,
        leaders: usize,
        next: &(dyn Fn() -> Option<u32> + Sync),
        report: &(dyn Fn(FrameResult) + Sync),
        idle: &(dyn Fn() + Sync),
    ) {
        let mut open = leaders;
        while open > 0 {
            while let Some((msg, status)) = self.comm.any_process().immediate_matched_probe() {
                let (from, tag) = (status.source_rank(), status.tag());
                let (bytes, _) = (msg, status).matched_receive_vec::<u8>();
                if tag != TAG_FRAME_REQUEST {
                    continue;
                }
                let k = next();
                if k.is_none() {
                    open -= 1;
                }
                let answer = k.map_or(NO_FRAME, u64::from);
                self.comm
                    .process_at_rank(from)
                    .send_with_tag(&bytes_of(answer)[..], TAG_FRAME);
                if bytes.is_empty() {
                    continue;
                }
                match decode_frame_result(&bytes) {
                    Some(r) => report(r),
                    None => super::abort::fail(&format!("rank {from} sent a corrupt frame report")),
                }
            }
            idle();
            std::thread::sleep(POLL);
        }
    }

    /// A leader of a group without rank 0: the next frame for its group (`None`: none left),
    /// after the group's previous frame `done` (none before the first).
    pub fn request(&self, done: Option<&FrameResult>) -> Option<u32> {
        let root = self.comm.process_at_rank(0);
        let report = done.map(encode_frame_result).unwrap_or_default();
        root.send_with_tag(&report[..], TAG_FRAME_REQUEST);
        loop {
            if let Some((msg, status)) = root.immediate_matched_probe_with_tag(TAG_FRAME) {
                let (bytes, _) = (msg, status).matched_receive_vec::<u8>();
                let k = word(&bytes);
                return (k != NO_FRAME).then_some(k as u32);
            }
            std::thread::sleep(POLL);
        }
    }
}
