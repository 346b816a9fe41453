//! Backends that integrate blocks of instances. Every backend implements [`Engine`]; the
//! [`Backend`] enum picks one.
//!
//! # Design
//! Guaranteed: instance i's inputs and results depend only on (campaign, seed, total, i), so the
//! CPU backend is bit-identical for any thread count, block size and shard split; the GPU backend
//! (`crate::gpu::engine`) is deterministic run to run and within 1e-3 of the CPU (docs/GPU.md).
//! The CPU backend integrates lane groups of [`crate::lanes::WIDTH`] instances in lockstep
//! (`simulate::simulate_lanes`; under Dormand–Prince a lane takes the next instance of its chunk
//! when its own ends), bit-identical to integrating each alone.

mod cpu;

pub use cpu::CpuEngine;

use crate::montecarlo::plan::{InstanceRecord, Plan};
use std::ops::Range;

/// A way to integrate instances.
pub trait Engine {
    /// Short name recorded in outputs ("cpu").
    fn name(&self) -> &'static str;
    /// What runs the instances, for run.json ("cpu: 2 threads").
    fn device(&self) -> String;
    /// Integrate the instances in `range`, returned in index order; `Err` says why the
    /// device failed (the CPU never does).
    fn run_block(&self, plan: &Plan, range: Range<u64>) -> Result<Vec<InstanceRecord>, String>;
}

/// The backend chosen on the command line.
pub enum Backend {
    Cpu(CpuEngine),
    Gpu(Box<crate::gpu::engine::GpuEngine>),
}

impl Backend {
    /// The engine behind the choice.
    pub fn engine(&self) -> &dyn Engine {
        match self {
            Backend::Cpu(e) => e,
            Backend::Gpu(e) => e.as_ref(),
        }
    }
}
