//! CPU backend: rayon over lane groups of [`WIDTH`] instances on a pool of a fixed size; each
//! group is integrated in lockstep SIMD lanes (`simulate::simulate_lanes`).

use super::Engine;
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
        let width = WIDTH as u64;
        let groups = (range.end - range.start).div_ceil(width);
        Ok(self.pool.install(|| {
            (0..groups)
                .into_par_iter()
                .flat_map_iter(|k| {
                    let start = range.start + k * width;
                    plan.run_lanes(start..(start + width).min(range.end))
                })
                .collect()
        }))
    }
}
