//! [`Master`], rank 0's side of a cluster job: it sends each node the scene to load and, per
//! frame, the [`FrameJob`]; hands out tiles on demand, k per render thread in advance so no
//! node waits for the network (paper 2.1); gathers the finished tiles and combines their
//! luminance statistics in tile order, so the image and the next frame's tone map never depend
//! on timing (paper 3.4).
//!
//! Faults: a tile held past the deadline (the previous frame's duration, at least a second) is
//! copied to another node and the first copy back counts; a node silent for longer than the
//! heartbeat timeout while it holds tiles ends the job with an error naming its rank.
//!
//! Frames pipeline: [`Master::finish`] returns as soon as the last tile of a frame is in, and
//! the caller starts the next frame with [`Master::begin`] before it shows or writes this one.

use crate::error::ClusterError;
use crate::protocol::{FrameJob, Message, PixelFormat, Ready, Setup, TilePixels, TileResult};
use crate::tile_queue::TileQueue;
use crate::transport::Transport;
use crate::worker::HEARTBEAT;
use igi_render::stats::{PhaseTimes, RayCounts};
use igi_render::tonemap::LuminanceStats;
use igi_render::{Film, TileGrid};
use std::time::{Duration, Instant};

/// How rank 0 schedules.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MasterConfig {
    /// Tiles each render thread of a node holds in advance (k ≥ 2 hides a round trip).
    pub tiles_ahead: u32,
    /// A node holding tiles and silent for this long is given up for dead.
    pub silence_limit: Duration,
    /// The shortest deadline after which a tile is copied to another node.
    pub min_deadline: Duration,
    /// How long nodes may take to load the scene.
    pub setup_limit: Duration,
}

impl Default for MasterConfig {
    fn default() -> Self {
        Self {
            tiles_ahead: 4,
            silence_limit: 6 * HEARTBEAT,
            min_deadline: Duration::from_secs(1),
            setup_limit: Duration::from_secs(600),
        }
    }
}

/// How long rank 0 waits on the transport before it checks deadlines and heartbeats.
const POLL: Duration = Duration::from_millis(2);

/// How often rank 0 looks for overdue tiles to copy.
const SWEEP: Duration = Duration::from_millis(10);

/// A render node as rank 0 sees it.
#[derive(Clone, Copy, Debug)]
struct Node {
    rank: usize,
    threads: u32,
    last_heard: Instant,
}

/// The frame in flight.
#[derive(Debug)]
struct Active {
    job: FrameJob,
    grid: TileGrid,
    queue: TileQueue,
    results: Vec<Option<(usize, TileResult)>>,
    started: Instant,
    bytes_in: u64,
    bytes_out: u64,
    /// Rank 0's time handling the frame's messages (decoding, checking, handing out).
    busy: Duration,
}

/// A frame gathered from the nodes.
#[derive(Clone, Debug)]
pub struct ClusterFrame {
    /// The job it answers.
    pub job: FrameJob,
    /// The tone-mapped 8-bit image ([`PixelFormat::Srgb8`] jobs), rows top to bottom.
    pub srgb8: Option<Vec<u8>>,
    /// The linear image ([`PixelFormat::Linear`] jobs).
    pub film: Option<Film>,
    /// Luminance statistics, combined in tile order.
    pub stats: LuminanceStats,
    /// Rays traced on all nodes.
    pub rays: RayCounts,
    /// Render time per phase, summed over all nodes' threads.
    pub times: PhaseTimes,
    /// VPLs of the frame.
    pub vpls: usize,
    /// Tiles each node contributed (index 0 is rank 1).
    pub tiles_per_node: Vec<u32>,
    /// Bytes of messages received for this frame (tiles, heartbeats).
    pub bytes_in: u64,
    /// Bytes of messages sent for this frame (frame jobs, tile numbers).
    pub bytes_out: u64,
    /// From [`Master::begin`] to the last tile.
    pub elapsed: Duration,
    /// Time rank 0 spent in [`Master::finish`] waiting for tiles.
    pub wait: Duration,
    /// Rank 0's own work on the frame: handling its messages and putting the image together.
    /// Rank 0 saturates when this reaches the frame time.
    pub busy: Duration,
}

/// Rank 0 of a cluster job.
#[derive(Debug)]
pub struct Master<T: Transport> {
    transport: T,
    nodes: Vec<Node>,
    config: MasterConfig,
    next_id: u64,
    active: Option<Active>,
    last_frame: Duration,
    /// Nodes that take part in frames: the first `in_use` (for scaling measurements).
    in_use: usize,
}

impl<T: Transport> Master<T> {
    /// Sends `setup` to every other rank and waits until each has loaded the scene with the
    /// digest rank 0 has.
    pub fn connect(transport: T, setup: &Setup, config: MasterConfig) -> Result<Self, ClusterError> {
        let size = transport.size();
        let mut master = Self {
            transport,
            nodes: Vec::new(),
            config,
            next_id: 1,
            active: None,
            last_frame: Duration::ZERO,
            in_use: 0,
        };
        if size < 2 {
            return Err(ClusterError::NoWorkers);
        }
        let bytes = Message::Setup(setup.clone()).encode();
        for rank in 1..size {
            master.transport.send(rank, &bytes)?;
        }
        let mut threads = vec![None; size];
        let start = Instant::now();
        while threads[1..].iter().any(Option::is_none) {
            if start.elapsed() > config.setup_limit {
                let rank = threads[1..].iter().position(Option::is_none).map_or(1, |i| i + 1);
                return Err(ClusterError::NodeLost { rank, silent: start.elapsed() });
            }
            let Some((rank, message)) = master.receive()? else { continue };
            match message {
                Message::Ready(Ready::Loaded { digest, threads: t }) if digest == setup.digest => {
                    threads[rank] = Some(t.max(1));
                }
                Message::Ready(Ready::Loaded { digest, .. }) => {
                    return Err(ClusterError::SceneMismatch { rank, ours: setup.digest, theirs: digest });
                }
                Message::Ready(Ready::Failed(message)) | Message::Fatal(message) => {
                    return Err(ClusterError::NodeFailed { rank, message });
                }
                Message::Heartbeat => {}
                other => return Err(protocol(rank, &other)),
            }
        }
        let now = Instant::now();
        master.nodes = (1..size)
            .map(|rank| Node { rank, threads: threads[rank].unwrap_or(1), last_heard: now })
            .collect();
        master.in_use = master.nodes.len();
        Ok(master)
    }

    /// Render threads over the nodes in use.
    pub fn threads(&self) -> usize {
        self.nodes[..self.in_use].iter().map(|n| n.threads as usize).sum()
    }

    /// Renders the next frames on the first `count` nodes only (at least one); the others
    /// idle. For measuring how the frame rate scales with the nodes.
    pub fn use_nodes(&mut self, count: usize) {
        self.in_use = count.clamp(1, self.nodes.len());
    }

    /// Number of render nodes.
    pub fn nodes(&self) -> usize {
        self.nodes.len()
    }

    /// Starts a frame: sends every node the job (its `id` is assigned here) and its first
    /// tiles. A frame still in flight is finished first.
    pub fn begin(&mut self, mut job: FrameJob) -> Result<(), ClusterError> {
        if self.active.is_some() {
            self.finish()?;
        }
        job.state.settings.validate()?;
        job.id = self.next_id;
        self.next_id += 1;
        let s = &job.state.settings;
        let grid = TileGrid::new(s.width, s.height, s.tile_size);
        let bytes = Message::Frame(Box::new(job.clone())).encode();
        let mut bytes_out = 0;
        for node in &self.nodes[..self.in_use] {
            self.transport.send(node.rank, &bytes)?;
            bytes_out += bytes.len() as u64;
        }
        self.active = Some(Active {
            job,
            grid,
            queue: TileQueue::new(grid.len()),
            results: vec![None; grid.len() as usize],
            started: Instant::now(),
            bytes_in: 0,
            bytes_out,
            busy: Duration::ZERO,
        });
        for i in 0..self.in_use {
            self.hand_out(i)?;
        }
        Ok(())
    }

    /// Waits for the last tile of the frame in flight and puts the frame together.
    pub fn finish(&mut self) -> Result<ClusterFrame, ClusterError> {
        let waiting = Instant::now();
        // Silence counts only while rank 0 listens: whatever nodes sent while it was busy
        // elsewhere (building its scene, writing the last frame) is still queued.
        self.nodes.iter_mut().for_each(|n| n.last_heard = waiting);
        let mut last_sweep = waiting;
        loop {
            let Some(active) = &self.active else {
                return Err(ClusterError::Protocol {
                    rank: 0,
                    message: "finish without a frame in flight".into(),
                });
            };
            if active.queue.is_complete() {
                break;
            }
            self.check_silence()?;
            if let Some((rank, message, len)) = self.receive_sized()? {
                let handling = Instant::now();
                let active = self.active.as_mut().unwrap_or_else(|| unreachable!("checked above"));
                active.bytes_in += len as u64;
                match message {
                    Message::Tile(result) => {
                        let Some(node) = self.nodes.iter().position(|n| n.rank == rank) else {
                            return Err(ClusterError::Protocol {
                                rank,
                                message: "a tile from an unknown rank".into(),
                            });
                        };
                        if result.job == active.job.id {
                            check_tile(rank, &active.job, &active.grid, &result)?;
                            if active.queue.complete(result.tile, rank) {
                                let slot = result.tile as usize;
                                active.results[slot] = Some((node, *result));
                            }
                            self.hand_out(node)?;
                        }
                    }
                    Message::Heartbeat => {}
                    Message::Fatal(message) => return Err(ClusterError::NodeFailed { rank, message }),
                    other => return Err(protocol(rank, &other)),
                }
                if let Some(active) = &mut self.active {
                    active.busy += handling.elapsed();
                }
            }
            // Once the fresh tiles are out, copies of overdue tiles go to nodes with room;
            // deadlines are a second or more, so looking every few milliseconds is enough.
            let fresh_left = self.active.as_ref().is_some_and(|a| a.queue.fresh() > 0);
            if !fresh_left && last_sweep.elapsed() >= SWEEP {
                last_sweep = Instant::now();
                for i in 0..self.in_use {
                    self.hand_out(i)?;
                }
            }
        }
        let wait = waiting.elapsed();
        let active = self.active.take().unwrap_or_else(|| unreachable!("checked in the loop"));
        self.last_frame = active.started.elapsed();
        Ok(assemble(active, self.nodes.len(), wait))
    }

    /// [`Master::begin`] and [`Master::finish`]: one frame, not pipelined.
    pub fn render(&mut self, job: FrameJob) -> Result<ClusterFrame, ClusterError> {
        self.begin(job)?;
        self.finish()
    }

    /// Tops node `i` up to its tiles in advance.
    fn hand_out(&mut self, i: usize) -> Result<(), ClusterError> {
        let Some(active) = &mut self.active else { return Ok(()) };
        let node = self.nodes[i];
        // k tiles per thread ahead, fewer as the frame runs out (guided scheduling): a node
        // left holding a full queue at the end would finish its last tiles alone.
        let threads: u32 = self.nodes[..self.in_use].iter().map(|n| n.threads).sum();
        let share = (active.queue.fresh() * node.threads).div_ceil(threads.max(1));
        let room = (node.threads * self.config.tiles_ahead).min(node.threads + share) as usize;
        let deadline = self.last_frame.max(self.config.min_deadline);
        let now = Instant::now();
        let mut tiles = Vec::new();
        while active.queue.held_by(node.rank) < room {
            match active.queue.take(node.rank, now, deadline) {
                Some(tile) => tiles.push(tile),
                None => break,
            }
        }
        if !tiles.is_empty() {
            let bytes = Message::Tiles { job: active.job.id, tiles }.encode();
            active.bytes_out += bytes.len() as u64;
            self.transport.send(node.rank, &bytes)?;
        }
        Ok(())
    }

    /// A node that holds tiles and has been silent too long ends the job.
    fn check_silence(&self) -> Result<(), ClusterError> {
        let Some(active) = &self.active else { return Ok(()) };
        let now = Instant::now();
        for node in &self.nodes[..self.in_use] {
            let silent = now.saturating_duration_since(node.last_heard);
            if silent > self.config.silence_limit && active.queue.held_by(node.rank) > 0 {
                return Err(ClusterError::NodeLost { rank: node.rank, silent });
            }
        }
        Ok(())
    }

    fn receive(&mut self) -> Result<Option<(usize, Message)>, ClusterError> {
        Ok(self.receive_sized()?.map(|(rank, message, _)| (rank, message)))
    }

    /// The next message within [`POLL`], its sender and its length; the sender counts as
    /// heard from.
    fn receive_sized(&mut self) -> Result<Option<(usize, Message, usize)>, ClusterError> {
        let Some((rank, bytes)) = self.transport.recv(POLL)? else { return Ok(None) };
        if let Some(node) = self.nodes.iter_mut().find(|n| n.rank == rank) {
            node.last_heard = Instant::now();
        }
        let message = Message::decode(&bytes).map_err(|error| ClusterError::Decode { rank, error })?;
        Ok(Some((rank, message, bytes.len())))
    }
}

impl<T: Transport> Drop for Master<T> {
    /// Every node stops when rank 0 does, whether the job ended or failed.
    fn drop(&mut self) {
        let bytes = Message::Shutdown.encode();
        for rank in 1..self.transport.size() {
            let _ = self.transport.send(rank, &bytes);
        }
    }
}

fn protocol(rank: usize, message: &Message) -> ClusterError {
    ClusterError::Protocol { rank, message: format!("unexpected {} message", message.kind()) }
}

/// A tile's pixels must have the job's format and the tile's size.
fn check_tile(rank: usize, job: &FrameJob, grid: &TileGrid, result: &TileResult) -> Result<(), ClusterError> {
    let bad = |message: String| Err(ClusterError::Protocol { rank, message });
    if result.tile >= grid.len() {
        return bad(format!("tile {} of a frame of {} tiles", result.tile, grid.len()));
    }
    let expected = grid.tile(result.tile).pixel_count();
    let format_ok = matches!(
        (&result.pixels, job.pixels),
        (TilePixels::Srgb8(b), PixelFormat::Srgb8) if b.len() % 3 == 0
    ) || matches!((&result.pixels, job.pixels), (TilePixels::Linear(_), PixelFormat::Linear));
    if !format_ok || result.pixels.len() != expected {
        return bad(format!(
            "tile {} with {} pixels of the wrong kind or count ({expected} expected)",
            result.tile,
            result.pixels.len()
        ));
    }
    Ok(())
}

/// The frame from its tiles, in tile order.
fn assemble(active: Active, nodes: usize, wait: Duration) -> ClusterFrame {
    let assembling = Instant::now();
    let s = &active.job.state.settings;
    let (width, height) = (s.width as usize, s.height as usize);
    let mut srgb8 = (active.job.pixels == PixelFormat::Srgb8).then(|| vec![0u8; 3 * width * height]);
    let mut film = (active.job.pixels == PixelFormat::Linear).then(|| Film::new(s.width, s.height));
    let mut stats = LuminanceStats::default();
    let mut rays = RayCounts::default();
    let mut times = PhaseTimes::default();
    let mut vpls = 0;
    let mut tiles_per_node = vec![0u32; nodes];
    for (index, slot) in active.results.into_iter().enumerate() {
        let Some((node, result)) = slot else { unreachable!("the queue is complete") };
        let tile = active.grid.tile(index as u32);
        match (&result.pixels, &mut srgb8, &mut film) {
            (TilePixels::Srgb8(bytes), Some(image), _) => {
                let row = 3 * tile.width() as usize;
                for (r, src) in bytes.chunks_exact(row).enumerate() {
                    let start = 3 * ((tile.y0 as usize + r) * width + tile.x0 as usize);
                    image[start..start + row].copy_from_slice(src);
                }
            }
            (TilePixels::Linear(pixels), _, Some(film)) => film.write_tile(&tile, pixels),
            _ => unreachable!("check_tile matched the format"),
        }
        stats = stats.merge(result.stats);
        rays += result.rays;
        times += result.times;
        vpls = result.vpls as usize;
        tiles_per_node[node] += 1;
    }
    ClusterFrame {
        srgb8,
        film,
        stats,
        rays,
        times,
        vpls,
        tiles_per_node,
        bytes_in: active.bytes_in,
        bytes_out: active.bytes_out,
        elapsed: active.started.elapsed(),
        wait,
        busy: active.busy + assembling.elapsed(),
        job: active.job,
    }
}
