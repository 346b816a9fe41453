//! CPU backend: rayon over chunks of instances on a pool of a fixed size; each chunk is
//! integrated in lockstep SIMD lane groups of [`WIDTH`] (`simulate::simulate_lanes`).

use super::Engine;
use crate::campaign::Integrator;
use crate::lanes::WIDTH;
use crate::montecarlo::plan::{InstanceRecord, Plan};
use rayon::prelude::*;
use std::ops::Range;

/// Integrates instances on `threads` worker threads.
pub struct CpuEngine {
    pool: rayon::ThreadPool,
    threads: usize,
}

impl CpuEngine {
    /// A pool of `threads` workers (0: one per core).
    pub fn new(threads: usize) -> Result<CpuEngine, rayon::ThreadPoolBuildError> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()?;
        let threads = pool.current_num_threads();
        Ok(CpuEngine { pool, threads })
    }

    /// Worker threads in the pool.
    pub fn threads(&self) -> usize {
        self.threads
    }
}

impl Engine for CpuEngine {
    fn name(&self) -> &'static str {
        "cpu"
    }

    fn device(&self) -> String {
        let s = if self.threads == 1 { "" } else { "s" };
        format!("cpu: {} thread{s}", self.threads)
    }

    fn run_block(&self, plan: &Plan, range: Range<u64>) -> Result<Vec<InstanceRecord>, String> {
        let chunk = chunk_size(plan, range.end - range.start, self.threads);
        let chunks = (range.end - range.start).div_ceil(chunk);
        Ok(self.pool.install(|| {
            (0..chunks)
                .into_par_iter()
                .flat_map_iter(|k| {
                    let start = range.start + k * chunk;
                    plan.run_lanes(start..(start + chunk).min(range.end))
                })
                .collect()
        }))
    }
}

/// Lane groups of error-controlled runs take up to this many instances each, in turn
/// (`simulate::adaptive::integrate`).
pub const MAX_ADAPTIVE_CHUNK: u64 = 16 * WIDTH as u64;

/// Instances per parallel task. Fixed-step RK4: one lane group ([`WIDTH`]), whose members take
/// the same steps unless their phases differ. Dormand–Prince: a lane group refilled from a
/// chunk of instances, as large as lets every thread have two chunks (so that the threads end
/// together), at most [`MAX_ADAPTIVE_CHUNK`]; a chunk's last members still leave lanes idle
/// while they run on, so larger chunks keep more of the group busy. Results do not depend on
/// it: each instance's numbers are its own.
fn chunk_size(plan: &Plan, instances: u64, threads: usize) -> u64 {
    let width = WIDTH as u64;
    match plan.campaign.stepping.integrator {
        Integrator::Rk4 => width,
        Integrator::Dopri5 => instances
            .div_ceil(2 * threads.max(1) as u64)
            .next_multiple_of(width)
            .clamp(width, MAX_ADAPTIVE_CHUNK),
    }
}
