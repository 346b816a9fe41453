//! The WGSL backend's host side: data layout shared with the shaders in `shaders/`.

pub mod layout;
pub mod props;
