//! CPU backend: rayon over instances on a pool of a fixed size.

use super::Engine;
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
        format!("cpu: {} threads", self.threads)
    }

    fn run_block(&self, plan: &Plan, range: Range<u64>) -> Result<Vec<InstanceRecord>, String> {
        Ok(self.pool.install(|| {
            range
                .into_par_iter()
                .map(|i| plan.run_instance(i))
                .collect()
        }))
    }
}
