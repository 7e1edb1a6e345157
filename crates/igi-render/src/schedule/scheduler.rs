//! The local tile scheduler: persistent worker threads that take tiles on demand from an
//! atomic counter (paper 2.1: demand-driven tiles balance the load because tiles cost
//! differently). The threads live as long as the [`TileScheduler`], so a sequence of frames
//! does not pay for thread start-up, and each keeps its scratch state across tiles.
//!
//! The results come back in tile order whatever thread rendered them, so anything combined
//! from them (the image, luminance statistics) is the same at any thread count. A
//! [`CancelToken`] stops the hand-out: each thread looks at it before taking a tile.

use crate::image::tile::{Tile, TileGrid};
use crate::schedule::cancel::{CancelToken, Cancelled};
use std::sync::Mutex;
use std::sync::atomic::{AtomicU32, Ordering};

/// A pool of render threads handing out tiles on demand.
#[derive(Debug)]
pub struct TileScheduler {
    pool: rayon::ThreadPool,
}

impl TileScheduler {
    /// A scheduler with `threads` workers (0: one per available core).
    pub fn new(threads: usize) -> Self {
        let threads =
            if threads > 0 { threads } else { std::thread::available_parallelism().map_or(1, |n| n.get()) };
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|i| format!("igi-render-{i}"))
            .build()
            .unwrap_or_else(|e| panic!("cannot start {threads} render threads: {e}"));
        Self { pool }
    }

    /// Runs `f` on the calling thread with the scheduler's threads as the pool of any rayon
    /// work inside it (so `--threads` bounds every phase of a frame).
    pub fn install<R: Send>(&self, f: impl FnOnce() -> R + Send) -> R {
        self.pool.install(f)
    }

    /// Number of worker threads.
    pub fn threads(&self) -> usize {
        self.pool.current_num_threads()
    }

    /// Renders every tile of `grid`: each worker makes its scratch state with `init` once,
    /// then calls `render(&mut scratch, tile)` for tile after tile taken from a shared
    /// counter, and `progress(done, total)` after each. Returns the results in tile order, or
    /// [`Cancelled`] if `cancel` stopped the threads before the last tile (each finishes the
    /// tile it is in).
    pub fn run<S, T, I, R>(
        &self,
        grid: &TileGrid,
        cancel: &CancelToken,
        init: I,
        render: R,
        progress: &(dyn Fn(u32, u32) + Sync),
    ) -> Result<Vec<T>, Cancelled>
    where
        T: Send,
        I: Fn() -> S + Sync,
        R: Fn(&mut S, Tile) -> T + Sync,
    {
        let next = AtomicU32::new(0);
        let total = grid.len();
        let finished = Mutex::new(Vec::with_capacity(total as usize));
        self.run_queue(
            || {
                let index = next.fetch_add(1, Ordering::Relaxed);
                (!cancel.is_cancelled() && index < total).then(|| grid.tile(index))
            },
            init,
            render,
            |tile, result| {
                let mut finished = finished.lock().unwrap_or_else(|e| e.into_inner());
                finished.push((tile.index, result));
                progress(finished.len() as u32, total);
            },
        );
        let mut all = finished.into_inner().unwrap_or_else(|e| e.into_inner());
        if all.len() < total as usize {
            return Err(Cancelled);
        }
        all.sort_unstable_by_key(|(index, _)| *index);
        Ok(all.into_iter().map(|(_, t)| t).collect())
    }

    /// Renders the tiles `next` hands out until it returns `None` on every thread: each worker
    /// makes its scratch state with `init` once, renders tile after tile and passes each
    /// result to `done` as soon as it is finished. A render node's tiles come this way, from
    /// the queue rank 0 keeps filling (paper 2.1).
    pub fn run_queue<S, T, I, R>(
        &self,
        next: impl Fn() -> Option<Tile> + Sync,
        init: I,
        render: R,
        done: impl Fn(Tile, T) + Sync,
    ) where
        I: Fn() -> S + Sync,
        R: Fn(&mut S, Tile) -> T + Sync,
    {
        self.pool.broadcast(|_| {
            let mut scratch = init();
            while let Some(tile) = next() {
                done(tile, render(&mut scratch, tile));
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_tile_once_in_order() {
        let grid = TileGrid::new(100, 70, 16);
        for threads in [1, 3] {
            let scheduler = TileScheduler::new(threads);
            assert_eq!(scheduler.threads(), threads);
            let out = scheduler.run(
                &grid,
                &CancelToken::new(),
                || 0u32,
                |n, t| {
                    *n += 1;
                    t.index
                },
                &|_, _| {},
            );
            assert_eq!(out, Ok((0..grid.len()).collect::<Vec<_>>()));
        }
    }

    #[test]
    fn no_tile_is_handed_out_once_cancelled() {
        let grid = TileGrid::new(256, 256, 8);
        for threads in [1, 3] {
            let scheduler = TileScheduler::new(threads);
            let cancel = CancelToken::new();
            let rendered = AtomicU32::new(0);
            let out = scheduler.run(
                &grid,
                &cancel,
                || (),
                |(), _| {
                    if rendered.fetch_add(1, Ordering::SeqCst) + 1 == 10 {
                        cancel.cancel();
                    }
                },
                &|_, _| {},
            );
            assert_eq!(out, Err(Cancelled));
            // The tenth tile, and at most one tile each other thread took before the cancel.
            let rendered = rendered.into_inner();
            assert!(rendered < 10 + threads as u32, "{rendered} of {} tiles rendered", grid.len());
        }
    }
}
