//! The WGSL backend's host side: adapters, the data layout shared with `shaders/`, and the
//! engine that runs the model kernel.

pub mod constants;
pub mod context;
pub mod engine;
pub mod layout;
pub mod params;
pub mod props;
