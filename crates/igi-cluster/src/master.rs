//! [`Master`], rank 0's side of a cluster job: it sends each node the scene to load and, per
//! frame, the [`FrameJob`]; hands out tiles on demand, k per render thread in advance so no
//! node waits for the network (paper 2.1); gathers the finished tiles and combines their
//! luminance statistics in tile order, so the image and the next frame's tone map never depend
//! on timing (paper 3.4).
//!
//! Faults (ARCHITECTURE.md, "Demand-driven tiles; a silent node's tiles go to the others"): a
//! node silent for a second (no tile, no heartbeat; it beats twice a second) is suspected: it
//! gets no more tiles and the ones it holds go to the other nodes at once, so the job carries on
//! at their rate; as soon as it is heard from again it gets the frame in flight and tiles. A
//! node silent for longer than the silence limit ends the job with an error naming its rank. A
//! tile held past the deadline (the previous frame's duration, at least a second) by a node
//! that still answers is copied to another node and the first copy back counts.
//!
//! Frames pipeline: [`Master::finish`] returns as soon as the last tile of a frame is in, and
//! the caller starts the next frame with [`Master::begin`] before it shows or writes this one.

use crate::error::ClusterError;
use crate::failure_detector::{FailureDetector, Lost};
use crate::protocol::{FrameJob, Message, Ready, Setup, TileResult};
use crate::tile_queue::TileQueue;
use crate::transport::Transport;
use crate::worker::HEARTBEAT;
use igi_render::image::stats::{PhaseTimes, RayCounts};
use igi_render::image::tonemap::LuminanceStats;
use igi_render::{CancelToken, FrameImage, FrameOutput, TileGrid};
use std::time::{Duration, Instant};

/// How rank 0 schedules.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MasterConfig {
    /// Tiles each render thread of a node holds in advance (k ≥ 2 hides a round trip).
    pub tiles_ahead: u32,
    /// A node silent for this long (while rank 0 listens) gets no tiles, and the ones it holds
    /// go to the other nodes, until it is heard from again.
    pub suspect_after: Duration,
    /// A node silent for this long is given up for lost: the job ends.
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
            // Two heartbeats missed: a node that answers sends far more often than that, and a
            // false suspicion costs only a few tiles rendered twice.
            suspect_after: 2 * HEARTBEAT,
            // While a node is silent the job runs at the other nodes' rate, so waiting costs
            // little; ending is for good (an MPI job cannot take a node back), so a node gets
            // ten seconds to come back from a pause (a stopped or swapping process).
            silence_limit: 20 * HEARTBEAT,
            min_deadline: Duration::from_secs(1),
            setup_limit: Duration::from_secs(600),
        }
    }
}

/// How long rank 0 waits on the transport before it checks deadlines and heartbeats.
const POLL: Duration = Duration::from_millis(2);

/// How often rank 0 looks for silent nodes and overdue tiles to copy.
const SWEEP: Duration = Duration::from_millis(10);

/// A render node as rank 0 sees it.
#[derive(Clone, Copy, Debug)]
struct Node {
    rank: usize,
    threads: u32,
    /// Id of the last frame job sent to it.
    job: u64,
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

/// A frame gathered from the nodes, and what the cluster did for it.
#[derive(Clone, Debug)]
pub struct ClusterFrame {
    /// The frame (its `elapsed`: from [`Master::begin`] to the last tile; its times: summed
    /// over all nodes' threads).
    pub output: FrameOutput,
    /// Tiles each node contributed (index 0 is rank 1).
    pub tiles_per_node: Vec<u32>,
    /// Bytes of messages received for this frame (tiles, heartbeats).
    pub bytes_in: u64,
    /// Bytes of messages sent for this frame (frame jobs, tile numbers).
    pub bytes_out: u64,
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
    /// Which nodes are silent, in the order of `nodes`.
    detector: FailureDetector,
    /// When rank 0 last looked for silent nodes and overdue tiles: kept across frames, so
    /// frames shorter than [`SWEEP`] are looked at too.
    swept: Instant,
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
            detector: FailureDetector::new(0, config.suspect_after, config.silence_limit),
            swept: Instant::now(),
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
        master.nodes =
            (1..size).map(|rank| Node { rank, threads: threads[rank].unwrap_or(1), job: 0 }).collect();
        master.in_use = master.nodes.len();
        master.detector =
            FailureDetector::new(master.nodes.len(), config.suspect_after, config.silence_limit);
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

    /// Starts a frame: sends every node in use that is not silent the job (its `id` is
    /// assigned here) and its first tiles. A frame still in flight is finished first.
    pub fn begin(&mut self, mut job: FrameJob) -> Result<(), ClusterError> {
        if self.active.is_some() {
            self.finish()?;
        }
        job.frame.settings.validate()?;
        job.id = self.next_id;
        self.next_id += 1;
        let s = &job.frame.settings;
        let grid = TileGrid::new(s.width, s.height, s.tile_size);
        let bytes = Message::Frame(Box::new(job.clone())).encode();
        let mut bytes_out = 0;
        for (i, node) in self.nodes[..self.in_use].iter_mut().enumerate() {
            if !self.detector.is_suspected(i) {
                self.transport.send(node.rank, &bytes)?;
                node.job = job.id;
                bytes_out += bytes.len() as u64;
            }
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
        let frame = self.finish_cancellable(&CancelToken::new())?;
        Ok(frame.unwrap_or_else(|| unreachable!("nothing cancels the frame")))
    }

    /// [`Master::finish`], unless `cancel` ends the wait first: then the frame is abandoned
    /// and `None` returned. Its tiles still on their way are dropped when they come (they
    /// carry its job id), and the nodes drop the tiles they hold when the next job comes.
    pub fn finish_cancellable(&mut self, cancel: &CancelToken) -> Result<Option<ClusterFrame>, ClusterError> {
        let waiting = Instant::now();
        // Silence counts only while rank 0 listens: whatever nodes sent while it was busy
        // elsewhere (building its scene, writing the last frame) is still queued.
        self.detector.listen(waiting);
        let gathered = self.gather(cancel);
        self.detector.pause(Instant::now());
        let complete = gathered?;
        let active = self.active.take().unwrap_or_else(|| unreachable!("gather checked it"));
        if !complete {
            return Ok(None);
        }
        self.last_frame = active.started.elapsed();
        Ok(Some(assemble(active, self.nodes.len(), waiting.elapsed())))
    }

    /// Handles messages until every tile of the frame in flight is in (`true`) or `cancel`
    /// asks to stop waiting (`false`).
    fn gather(&mut self, cancel: &CancelToken) -> Result<bool, ClusterError> {
        loop {
            let Some(active) = &self.active else {
                return Err(ClusterError::Protocol {
                    rank: 0,
                    message: "finish without a frame in flight".into(),
                });
            };
            if active.queue.is_complete() {
                return Ok(true);
            }
            if cancel.is_cancelled() {
                return Ok(false);
            }
            if let Some((rank, message, len)) = self.receive_sized()? {
                self.handle(rank, message, len)?;
            }
            // Silence and deadlines are a second or more: looking every few milliseconds is
            // enough. Once no tile is waiting, copies of overdue tiles go to nodes with room.
            if self.swept.elapsed() >= SWEEP {
                self.swept = Instant::now();
                self.watch()?;
                if self.active.as_ref().is_some_and(|a| a.queue.waiting() == 0) {
                    for i in 0..self.in_use {
                        self.hand_out(i)?;
                    }
                }
            }
        }
    }

    /// A message from `rank` while a frame is in flight.
    fn handle(&mut self, rank: usize, message: Message, len: usize) -> Result<(), ClusterError> {
        let handling = Instant::now();
        let node = self.index(rank);
        let Some(active) = self.active.as_mut() else { return Ok(()) };
        active.bytes_in += len as u64;
        match message {
            Message::Tile(result) => {
                let Some(node) = node else {
                    return Err(ClusterError::Protocol {
                        rank,
                        message: "a tile from an unknown rank".into(),
                    });
                };
                // Tiles of earlier frames (late copies, or a node that was silent catching
                // up) are dropped.
                if result.job == active.job.id {
                    check_tile(rank, &active.job, &active.grid, &result)?;
                    if active.queue.complete(result.tile) {
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
        Ok(())
    }

    /// [`Master::begin`] and [`Master::finish`]: one frame, not pipelined.
    pub fn render(&mut self, job: FrameJob) -> Result<ClusterFrame, ClusterError> {
        self.begin(job)?;
        self.finish()
    }

    /// Tops node `i` up to its tiles in advance, if it works on the frame and answers.
    fn hand_out(&mut self, i: usize) -> Result<(), ClusterError> {
        let Some(active) = &mut self.active else { return Ok(()) };
        let node = self.nodes[i];
        let working = |(i, n): (usize, &Node)| n.job == active.job.id && !self.detector.is_suspected(i);
        if !working((i, &node)) {
            return Ok(());
        }
        // k tiles per thread ahead, fewer as the frame runs out (guided scheduling): a node
        // left holding a full queue at the end would finish its last tiles alone.
        let threads: u32 = self.nodes[..self.in_use]
            .iter()
            .enumerate()
            .filter(|&n| working(n))
            .map(|(_, n)| n.threads)
            .sum();
        let share = (active.queue.waiting() * node.threads).div_ceil(threads.max(1));
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

    /// Suspects the nodes that have fallen silent and hands the tiles they hold to the others;
    /// a node silent past the limit ends the job.
    fn watch(&mut self) -> Result<(), ClusterError> {
        let now = Instant::now();
        let suspects = self.detector.check(now).map_err(|lost| self.lost(lost))?;
        if suspects.is_empty() {
            return Ok(());
        }
        for &i in &suspects {
            let rank = self.nodes[i].rank;
            let held = self.active.as_mut().map_or(0, |a| a.queue.withdraw(rank));
            tracing::warn!(
                "rank {rank} has not answered for {:.1} s: the other nodes render its {held} tile(s) and its share until it answers (at most {:.0} s)",
                self.detector.silence(i, now).as_secs_f64(),
                self.config.silence_limit.as_secs_f64()
            );
        }
        for i in 0..self.in_use {
            self.hand_out(i)?;
        }
        Ok(())
    }

    /// Node `i`, silent for a while, answers again: it gets the frame in flight (unless it has
    /// it) and tiles.
    fn rejoin(&mut self, i: usize) -> Result<(), ClusterError> {
        tracing::warn!("rank {} answers again", self.nodes[i].rank);
        let Some(active) = &mut self.active else { return Ok(()) };
        if i < self.in_use && self.nodes[i].job != active.job.id {
            let bytes = Message::Frame(Box::new(active.job.clone())).encode();
            active.bytes_out += bytes.len() as u64;
            self.transport.send(self.nodes[i].rank, &bytes)?;
            self.nodes[i].job = active.job.id;
        }
        self.hand_out(i)
    }

    fn lost(&self, lost: Lost) -> ClusterError {
        ClusterError::NodeLost { rank: self.nodes[lost.node].rank, silent: lost.silent }
    }

    /// The position of `rank` in `nodes` (which holds ranks 1, 2, … in order).
    fn index(&self, rank: usize) -> Option<usize> {
        rank.checked_sub(1).filter(|&i| i < self.nodes.len())
    }

    fn receive(&mut self) -> Result<Option<(usize, Message)>, ClusterError> {
        Ok(self.receive_sized()?.map(|(rank, message, _)| (rank, message)))
    }

    /// The next message within [`POLL`], its sender and its length; the sender counts as
    /// heard from (and rejoins the frame if it was silent).
    fn receive_sized(&mut self) -> Result<Option<(usize, Message, usize)>, ClusterError> {
        let Some((rank, bytes)) = self.transport.recv(POLL)? else { return Ok(None) };
        if let Some(i) = self.index(rank) {
            if self.detector.heard(i, Instant::now()) {
                self.rejoin(i)?;
            }
        }
        let message = Message::decode(&bytes).map_err(|error| ClusterError::Decode { rank, error })?;
        Ok(Some((rank, message, bytes.len())))
    }
}

impl<T: Transport> Drop for Master<T> {
    /// Every node stops when rank 0 does, whether the job ended or failed. A job ends only
    /// once every rank does (`MPI_Finalize` waits for all), so rank 0 waits until every node
    /// has said [`Message::Bye`]; a node silent for longer than the silence limit instead
    /// (stopped, say) aborts the job with a message naming its rank, rather than leave it
    /// hanging.
    fn drop(&mut self) {
        self.active = None;
        let bytes = Message::Shutdown.encode();
        for rank in 1..self.transport.size() {
            let _ = self.transport.send(rank, &bytes);
        }
        if let Err(lost) = self.await_byes() {
            tracing::error!("{lost}");
            self.transport.abort(1);
        }
    }
}

impl<T: Transport> Master<T> {
    /// Listens until every node has said [`Message::Bye`]; one silent past the limit first is
    /// lost. If the transport fails there is no one left to wait for.
    fn await_byes(&mut self) -> Result<(), ClusterError> {
        let mut staying = vec![true; self.nodes.len()];
        self.detector.listen(Instant::now());
        while staying.contains(&true) {
            let now = Instant::now();
            let silent = |i: usize| self.detector.silence(i, now);
            if let Some(i) = (0..staying.len()).find(|&i| staying[i] && silent(i) > self.config.silence_limit)
            {
                return Err(ClusterError::NodeLost { rank: self.nodes[i].rank, silent: silent(i) });
            }
            match self.receive_sized() {
                Ok(Some((rank, Message::Bye, _))) => {
                    if let Some(i) = self.index(rank) {
                        staying[i] = false;
                    }
                }
                Ok(_) => {}
                Err(_) => return Ok(()),
            }
        }
        Ok(())
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
    let expected = grid.tile(result.tile).rect.pixel_count();
    let count = result.pixels.pixel_count();
    if !result.pixels.fits(job.frame.pixels) || count != Some(expected) {
        return bad(format!(
            "tile {} with {} pixels of the wrong kind or count ({expected} expected)",
            result.tile,
            count.map_or("an inconsistent number of".into(), |n| n.to_string())
        ));
    }
    Ok(())
}

/// The frame from its tiles, in tile order.
fn assemble(active: Active, nodes: usize, wait: Duration) -> ClusterFrame {
    let assembling = Instant::now();
    let frame = &active.job.frame;
    let mut stats = LuminanceStats::default();
    let mut rays = RayCounts::default();
    let mut times = PhaseTimes::default();
    let mut vpls = 0;
    let mut tiles_per_node = vec![0u32; nodes];
    let mut pixels = Vec::with_capacity(active.results.len());
    for (index, slot) in active.results.into_iter().enumerate() {
        let Some((node, result)) = slot else { unreachable!("the queue is complete") };
        pixels.push((active.grid.tile(index as u32), result.pixels));
        stats = stats.merge(result.stats);
        rays += result.rays;
        times += result.times;
        vpls = result.vpls as usize;
        tiles_per_node[node] += 1;
    }
    let s = &frame.settings;
    let image = FrameImage::from_tiles(frame.pixels, s.width, s.height, pixels);
    ClusterFrame {
        output: FrameOutput { image, stats, rays, times, elapsed: active.started.elapsed(), vpls },
        tiles_per_node,
        bytes_in: active.bytes_in,
        bytes_out: active.bytes_out,
        wait,
        busy: active.busy + assembling.elapsed(),
    }
}
