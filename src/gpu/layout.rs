//! Rust ↔ WGSL data layout: every struct the kernels read or write is declared once here with
//! [`gpu_struct!`], which derives the `#[repr(C)]` bytemuck type and emits the matching WGSL
//! declaration, so the two cannot disagree. Fields are `f32`, `u32`, `[f32; N]` or other such
//! structs only: their alignment is 4 in both languages, so neither side inserts padding
//! (storage buffers only).

/// WGSL spelling of a field type.
pub trait WgslType {
    /// The type as WGSL writes it.
    fn wgsl() -> String;
}

impl WgslType for f32 {
    fn wgsl() -> String {
        "f32".into()
    }
}

impl WgslType for u32 {
    fn wgsl() -> String {
        "u32".into()
    }
}

impl<const N: usize> WgslType for [f32; N] {
    fn wgsl() -> String {
        format!("array<f32, {N}>")
    }
}

/// Declares a `#[repr(C)]` Pod struct and a `wgsl()` function returning its WGSL declaration;
/// the struct may itself be a field of another (WGSL aligns it to 4 as well).
#[macro_export]
macro_rules! gpu_struct {
    ($(#[$m:meta])* pub struct $name:ident { $($(#[$fm:meta])* pub $field:ident : $ty:ty),* $(,)? }) => {
        $(#[$m])*
        #[repr(C)]
        #[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
        pub struct $name { $($(#[$fm])* pub $field: $ty),* }

        impl $name {
            /// The WGSL declaration of this struct.
            pub fn wgsl() -> String {
                let mut s = format!("struct {} {{\n", stringify!($name));
                $( s += &format!("    {}: {},\n", stringify!($field), <$ty as $crate::gpu::layout::WgslType>::wgsl()); )*
                s += "}\n";
                s
            }
        }

        impl $crate::gpu::layout::WgslType for $name {
            fn wgsl() -> String {
                stringify!($name).into()
            }
        }
    };
}
