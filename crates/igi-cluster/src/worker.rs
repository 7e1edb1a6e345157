//! The render node (ranks 1..N): loads the scene rank 0 names, then for every frame poses it,
//! derives the VPLs from the [`FrameJob`] itself, and renders, filters and tone-maps the tiles
//! rank 0 hands it, sending each back as soon as it is done (paper sections 2.1 and 3.4).
//!
//! The node's persistent render threads (a [`FrameRenderer`]'s) take tiles from a local queue
//! that rank 0 keeps k tiles deep per thread, so a thread never waits for the network between
//! tiles. The calling thread alone talks to the transport (MPI's "funneled" threading): it forwards finished tiles, queues new tile numbers
//! and sends a heartbeat twice a second, also while a long tile renders. When a newer job or a
//! shutdown comes, it cancels the job's [`CancelToken`]: the render threads take no further
//! tile of it (each finishes the one it is in) and the queued tiles are dropped.

use crate::error::ClusterError;
use crate::protocol::{FrameJob, Message, PROTOCOL_VERSION, Ready, Setup, TileResult};
use crate::transport::Transport;
use igi_render::image::frame_image::TileOutput;
use igi_render::{CancelToken, FrameRenderer, PreparedScene, add_default_light};
use igi_scene::Scene;
use std::collections::VecDeque;
use std::sync::mpsc::{RecvTimeoutError, channel};
use std::sync::{Condvar, Mutex};
use std::time::{Duration, Instant};

/// How often a node tells rank 0 it is alive.
pub const HEARTBEAT: Duration = Duration::from_millis(500);

/// How long the transport thread waits for a finished tile before it looks for messages.
const POLL: Duration = Duration::from_millis(1);

/// What a node did, for its log line.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WorkerSummary {
    /// Frames it took part in.
    pub frames: u64,
    /// Tiles it rendered.
    pub tiles: u64,
}

/// Runs a render node until rank 0 says stop. `load` turns rank 0's [`Setup`] into the scene
/// (from the node's own files or the ones sent along); `threads` render threads (0: one per
/// core).
pub fn run_worker<T: Transport>(
    transport: &mut T,
    threads: usize,
    load: impl FnOnce(&Setup) -> Result<Scene, String>,
) -> Result<WorkerSummary, ClusterError> {
    let setup = loop {
        match next_from_root(transport, HEARTBEAT)? {
            Some(Message::Setup(setup)) => break setup,
            Some(Message::Shutdown) => return Ok(WorkerSummary::default()),
            Some(other) => return Err(unexpected(0, &other, "the scene setup")),
            None => {}
        }
    };
    let renderer = FrameRenderer::new(threads);
    let loaded = if setup.version != PROTOCOL_VERSION {
        Err(format!(
            "rank 0 speaks protocol {}, this node {PROTOCOL_VERSION}: run the same igi on every rank",
            setup.version
        ))
    } else {
        load(&setup)
    };
    let mut scene = match loaded {
        Ok(scene) => {
            let digest = scene.digest();
            let mut prepared = PreparedScene::new(scene);
            // Rank 0 says what this adds; the nodes add the same light silently.
            add_default_light(&mut prepared, setup.default_light, setup.view.as_ref());
            let ready = Ready::Loaded { digest, threads: renderer.threads() as u32 };
            transport.send(0, &Message::Ready(ready).encode())?;
            prepared
        }
        Err(message) => {
            transport.send(0, &Message::Ready(Ready::Failed(message.clone())).encode())?;
            return Err(ClusterError::NodeFailed { rank: transport.rank(), message });
        }
    };

    let mut summary = WorkerSummary::default();
    let mut next = None;
    let mut last_beat = Instant::now();
    loop {
        let message = match next.take() {
            Some(m) => m,
            None => match next_from_root(transport, HEARTBEAT)? {
                Some(m) => m,
                None => {
                    transport.send(0, &Message::Heartbeat.encode())?;
                    last_beat = Instant::now();
                    continue;
                }
            },
        };
        match message {
            Message::Frame(job) => {
                summary.frames += 1;
                let (tiles, after) = render_job(transport, &renderer, &mut scene, &job, &mut last_beat)?;
                summary.tiles += tiles;
                match after {
                    Some(Message::Shutdown) => break,
                    other => next = other,
                }
            }
            Message::Shutdown => break,
            // Tile numbers of a job this node has left behind: rank 0 has moved on.
            Message::Tiles { .. } => {}
            other => return Err(unexpected(0, &other, "a frame")),
        }
    }
    // Rank 0 ends the job once every node has said this (a stopped node ends it with an error).
    transport.send(0, &Message::Bye.encode())?;
    Ok(summary)
}

/// The next message from rank 0 within `timeout` (messages from other ranks are a protocol
/// error: nodes do not talk to each other).
fn next_from_root<T: Transport>(
    transport: &mut T,
    timeout: Duration,
) -> Result<Option<Message>, ClusterError> {
    let Some((rank, bytes)) = transport.recv(timeout)? else { return Ok(None) };
    let message = Message::decode(&bytes).map_err(|error| ClusterError::Decode { rank, error })?;
    if rank != 0 {
        return Err(unexpected(rank, &message, "nothing from another node"));
    }
    Ok(Some(message))
}

fn unexpected(rank: usize, message: &Message, expected: &str) -> ClusterError {
    ClusterError::Protocol { rank, message: format!("sent {} where {expected} was expected", message.kind()) }
}

/// The tile queue the render threads share with the transport thread, and the job's token.
struct LocalQueue {
    tiles: Mutex<VecDeque<u32>>,
    ready: Condvar,
    cancel: CancelToken,
}

impl LocalQueue {
    /// The next tile, waiting for one; `None` once the job is cancelled.
    fn pop(&self) -> Option<u32> {
        let mut tiles = self.tiles.lock().unwrap_or_else(|e| e.into_inner());
        loop {
            if self.cancel.is_cancelled() {
                return None;
            }
            if let Some(tile) = tiles.pop_front() {
                return Some(tile);
            }
            tiles = self.ready.wait(tiles).unwrap_or_else(|e| e.into_inner());
        }
    }

    fn push(&self, tiles: &[u32]) {
        self.tiles.lock().unwrap_or_else(|e| e.into_inner()).extend(tiles);
        self.ready.notify_all();
    }

    /// Cancels the job and wakes the threads waiting for tiles.
    fn cancel(&self) {
        self.cancel.cancel();
        // Under the lock, so no thread is between its look at the token and its wait.
        let _tiles = self.tiles.lock().unwrap_or_else(|e| e.into_inner());
        self.ready.notify_all();
    }
}

/// Renders the tiles rank 0 hands out for `job` until it moves on. Returns the tiles rendered
/// and the message that ended the job (the next frame or a shutdown).
fn render_job<T: Transport>(
    transport: &mut T,
    renderer: &FrameRenderer,
    scene: &mut PreparedScene,
    job: &FrameJob,
    last_beat: &mut Instant,
) -> Result<(u64, Option<Message>), ClusterError> {
    let rank = transport.rank();
    // Posing the scene and the walks of a large scene can take longer than rank 0's
    // patience: keep beating.
    let plan = std::thread::scope(|s| -> Result<_, ClusterError> {
        let (planned_tx, planned) = channel();
        s.spawn(move || {
            let _ = planned_tx.send(renderer.plan(scene, &job.frame));
        });
        loop {
            match planned.recv_timeout(HEARTBEAT) {
                Ok(plan) => return Ok(plan),
                Err(RecvTimeoutError::Timeout) => {
                    transport.send(0, &Message::Heartbeat.encode())?;
                    *last_beat = Instant::now();
                }
                Err(RecvTimeoutError::Disconnected) => {
                    return Err(ClusterError::NodeFailed {
                        rank,
                        message: "the VPL generation panicked".into(),
                    });
                }
            }
        }
    })?;
    let plan = match plan {
        Ok(plan) => plan,
        Err(e) => {
            let message = format!("frame {} has invalid settings: {e}", job.id);
            transport.send(0, &Message::Fatal(message.clone()).encode())?;
            return Err(ClusterError::NodeFailed { rank, message });
        }
    };
    let vpl_count = u32::try_from(plan.vpl_count()).unwrap_or(u32::MAX);
    let grid = plan.grid;
    let frame_tiles = plan.tiles();
    let queue =
        LocalQueue { tiles: Mutex::new(VecDeque::new()), ready: Condvar::new(), cancel: CancelToken::new() };
    let (done_tx, done_rx) = channel::<TileOutput>();
    let mut rendered = 0;

    std::thread::scope(|threads| -> Result<(u64, Option<Message>), ClusterError> {
        // The renderer's persistent threads take the tiles as rank 0 queues them; this
        // thread only waits for them to finish.
        let (queue, frame_tiles) = (&queue, &frame_tiles);
        threads.spawn(move || {
            renderer.scheduler().run_queue(
                || queue.pop().map(|index| grid.tile(index)),
                || renderer.lend_scratch(),
                |scratch, tile| frame_tiles.render(tile, scratch),
                |_, out| {
                    // The receiver is gone only once the job is over (and cancelled).
                    let _ = done_tx.send(out);
                },
            );
        });
        // Cancels the job however this thread leaves (a newer job, a shutdown, an error), so
        // the render threads end after the tile they are in.
        struct CancelOnExit<'q>(&'q LocalQueue);
        impl Drop for CancelOnExit<'_> {
            fn drop(&mut self) {
                self.0.cancel();
            }
        }
        let _cancel = CancelOnExit(queue);
        loop {
            // Every message waiting first (the tiles of a new frame come right behind it),
            // then wait on the render threads: one probe per wait, so this thread takes next
            // to no CPU from the render threads.
            while let Some(message) = next_from_root(transport, Duration::ZERO)? {
                match message {
                    Message::Tiles { job: id, tiles } if id == job.id => {
                        if let Some(&bad) = tiles.iter().find(|&&t| t >= grid.len()) {
                            let message = format!("tile {bad} of frame {id}, which has {} tiles", grid.len());
                            transport.send(0, &Message::Fatal(message.clone()).encode())?;
                            return Err(ClusterError::Protocol { rank: 0, message });
                        }
                        queue.push(&tiles);
                    }
                    Message::Tiles { .. } => {}
                    // Rank 0 moves on only once every tile of this job is back: whatever this
                    // node still holds is a late copy.
                    m @ (Message::Frame(_) | Message::Shutdown) => return Ok((rendered, Some(m))),
                    other => return Err(unexpected(0, &other, "tiles or a frame")),
                }
            }
            let mut finished = match done_rx.recv_timeout(POLL) {
                Ok(out) => Some(out),
                Err(RecvTimeoutError::Timeout) => None,
                Err(RecvTimeoutError::Disconnected) => {
                    return Err(ClusterError::NodeFailed { rank, message: "a render thread died".into() });
                }
            };
            while let Some(out) = finished {
                let result = tile_result(job, out, vpl_count);
                transport.send(0, &Message::Tile(Box::new(result)).encode())?;
                rendered += 1;
                finished = done_rx.try_recv().ok();
            }
            if last_beat.elapsed() >= HEARTBEAT {
                transport.send(0, &Message::Heartbeat.encode())?;
                *last_beat = Instant::now();
            }
        }
    })
}

/// The message for a finished tile: its pixels in the job's format, its statistics and costs.
fn tile_result(job: &FrameJob, out: TileOutput, vpls: u32) -> TileResult {
    TileResult {
        job: job.id,
        tile: out.tile.index,
        pixels: out.pixels,
        stats: out.stats,
        rays: out.rays,
        times: out.times,
        vpls,
    }
}
