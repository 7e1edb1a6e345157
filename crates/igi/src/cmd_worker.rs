//! `igi worker`: a render node and nothing else, for the split launch of a viewer on rank 0
//! (`mpirun -n 1 igi view SCENE --cluster : -n 3 igi worker`). It loads the scene rank 0
//! names and renders tiles until rank 0 ends the job.

use anyhow::Result;
use clap::Args;

/// Arguments of `igi worker`.
#[derive(Debug, Args)]
pub struct WorkerArgs {
    /// Render threads (0: one per core).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
}

/// Runs `igi worker`.
pub fn run(args: &WorkerArgs) -> Result<()> {
    crate::cluster::work(args.threads)
}
