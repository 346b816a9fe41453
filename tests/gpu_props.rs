//! The WGSL property library (`props_wgsl()`) against the Rust f64 functions it mirrors: one
//! compute dispatch evaluates every `fl_*`, `he_*` and `tank_*` function on a grid of f32
//! inputs for every propellant and for one tank of each shape (plus a prolate capsule),
//! and each result must agree with the Rust value at the same (f32) input to the tolerance
//! listed per function, including the slosh modes (`tank_slosh_modes`: the generated tables of
//! `model::slosh_table` as WGSL constants against `model::slosh::tank_modes`, so that a table or
//! interpolation mismatch between the backends shows here). Skipped (with a message) when there
//! is no GPU adapter, unless `CRYOSLOSH_REQUIRE_GPU=1`.

mod common;

use cryoslosh::fluids::{Fluid, FluidProps, HELIUM};
use cryoslosh::geometry::{Shape, Tank, TankLanes};
use cryoslosh::gpu::props::{props_wgsl, slosh_table_f32, GpuFluid, GpuGas, GpuTank};
use cryoslosh::gpu_struct;
use cryoslosh::model::slosh::{tank_modes, ModeShape};

gpu_struct! {
    /// One evaluation: function number `func` on fluid or tank number `obj` at `arg`.
    pub struct Case {
        pub func: u32,
        pub obj: u32,
        pub arg: f32,
    }
}

/// Which input grid a function is evaluated on.
#[derive(Clone, Copy)]
enum Grid {
    /// Liquid temperatures: the fitted range and some way beyond it (K).
    LiquidT,
    /// Gas temperatures 0 .. 20 000 K, log-spaced inside the power-law clamp.
    GasT,
    /// Pressures: P_sat over the range, plus below, above, zero and negative (Pa).
    Pressure,
    /// Enthalpies: h_l over the liquid grid, including negative and above h_l(t_max) (J/kg).
    Enthalpy,
    /// Heights -1 m .. H + 1 m, dense near the poles and region boundaries.
    Height,
    /// Volumes -1 .. V + 1 (m³), from the height grid.
    Volume,
    /// No argument.
    None,
}

/// Rust reference of a fluid function.
type FluidFn = fn(&FluidProps, f64) -> f64;
/// Rust reference of a tank function.
type TankFn = fn(&Tank, f64) -> f64;

/// WGSL call (argument `a`), input grid, Rust reference and max relative error allowed.
const FLUID_FUNCS: [(&str, Grid, FluidFn, f64); 28] = [
    ("fl_psat_pa(a)", Grid::LiquidT, |f, t| f.psat_pa(t), 5e-6),
    (
        "fl_dpsat_dt(a)",
        Grid::LiquidT,
        |f, t| f.dpsat_dt_pa_per_k(t),
        5e-6,
    ),
    ("fl_tsat_k(a)", Grid::Pressure, |f, p| f.tsat_k(p), 1e-6),
    (
        "fl_rho_l(a)",
        Grid::LiquidT,
        |f, t| f.rho_l_kg_per_m3(t),
        1e-6,
    ),
    (
        "fl_drho_l_dt(a)",
        Grid::LiquidT,
        |f, t| f.drho_l_dt(t),
        5e-6,
    ),
    (
        "fl_cp_l(a)",
        Grid::LiquidT,
        |f, t| f.cp_l_j_per_kg_k(t),
        1e-6,
    ),
    ("fl_h_l(a)", Grid::LiquidT, |f, t| f.h_l_j_per_kg(t), 1e-6),
    (
        "fl_t_from_h_l(a)",
        Grid::Enthalpy,
        |f, h| f.t_from_h_l_k(h),
        1e-6,
    ),
    ("fl_h_fg(a)", Grid::LiquidT, |f, t| f.h_fg_j_per_kg(t), 1e-6),
    ("fl_k_l(a)", Grid::LiquidT, |f, t| f.k_l_w_per_m_k(t), 1e-6),
    (
        "fl_rho_v_sat(a)",
        Grid::LiquidT,
        |f, t| f.rho_v_sat_kg_per_m3(t),
        5e-6,
    ),
    (
        "fl_vapor_state(a, fl_rho_v_sat(a)).z",
        Grid::LiquidT,
        |f, t| f.vapor_z_u_res(t, f.rho_v_sat_kg_per_m3(t)).0,
        2e-6,
    ),
    (
        "fl_vapor_state(a, fl_rho_v_sat(a)).u_res",
        Grid::LiquidT,
        |f, t| f.vapor_u_res_j_per_kg(t, f.rho_v_sat_kg_per_m3(t)),
        3e-5,
    ),
    (
        "fl_vapor_state(a, fl_rho_v_sat(a)).du_res_dt",
        Grid::LiquidT,
        |f, t| f.vapor_state(t, f.rho_v_sat_kg_per_m3(t)).du_res_dt,
        1e-4,
    ),
    (
        "fl_vapor_state(a, fl_rho_v_sat(a)).du_res_drho",
        Grid::LiquidT,
        |f, t| f.vapor_state(t, f.rho_v_sat_kg_per_m3(t)).du_res_drho,
        1e-4,
    ),
    (
        "fl_vapor_state(a, fl_rho_v_sat(a)).dp_dt",
        Grid::LiquidT,
        |f, t| f.vapor_state(t, f.rho_v_sat_kg_per_m3(t)).dp_dt,
        1e-5,
    ),
    (
        "fl_vapor_state(a, fl_rho_v_sat(a)).dp_drho",
        Grid::LiquidT,
        |f, t| f.vapor_state(t, f.rho_v_sat_kg_per_m3(t)).dp_drho,
        1e-5,
    ),
    // f32 Horner over 16 monomial coefficients up to |67| (para-hydrogen): a few 1e-5.
    (
        "fl_vapor_ideal(a).y",
        Grid::GasT,
        |f, t| f.vapor_ideal(t).1,
        5e-5,
    ),
    // u⁰ crosses zero on the fit's own reference: shifted by 1e7 J/kg (at 300 K, 5e-5 of that
    // bounds the absolute error at 500 J/kg, 1e-4 of hydrogen's u⁰ there).
    (
        "fl_vapor_ideal(a).x + 1.0e7",
        Grid::GasT,
        |f, t| f.vapor_ideal(t).0 + 1.0e7,
        5e-5,
    ),
    // Near saturation (1.5 T at P_sat(T), at most 2 MPa), where Z − 1 is largest.
    (
        "fl_vapor_h_res_at_tp(1.5 * a, min(fl_psat_pa(a), 2.0e6)) + 1.5 * a * fl_r_specific()",
        Grid::LiquidT,
        |f, t| {
            let p = f.psat_pa(t).min(2.0e6);
            f.vapor_h_res_at_tp(1.5 * t, p) + 1.5 * t * f.r_specific_j_per_kg_k()
        },
        1e-4,
    ),
    // A warm vapour (4 T) at P_sat(T) (at most 2 MPa); plus R T so that it stays away from zero.
    (
        "fl_vapor_h_res_at_tp(4.0 * a, min(fl_psat_pa(a), 2.0e6)) + 4.0 * a * fl_r_specific()",
        Grid::LiquidT,
        |f, t| {
            let p = f.psat_pa(t).min(2.0e6);
            f.vapor_h_res_at_tp(4.0 * t, p) + 4.0 * t * f.r_specific_j_per_kg_k()
        },
        2e-5,
    ),
    ("fl_mu_l(a)", Grid::LiquidT, |f, t| f.mu_l_pa_s(t), 5e-6),
    ("fl_k_v(a)", Grid::GasT, |f, t| f.k_v_w_per_m_k(t), 5e-6),
    ("fl_mu_v(a)", Grid::GasT, |f, t| f.mu_v_pa_s(t), 5e-6),
    (
        "fl_r_specific()",
        Grid::None,
        |f, _| f.r_specific_j_per_kg_k(),
        1e-7,
    ),
    ("he_k(a)", Grid::GasT, |_, t| HELIUM.k_w_per_m_k(t), 5e-6),
    ("he_mu(a)", Grid::GasT, |_, t| HELIUM.mu_pa_s(t), 5e-6),
    (
        "he_r_specific()",
        Grid::None,
        |_, _| HELIUM.r_specific_j_per_kg_k(),
        1e-7,
    ),
];

/// WGSL call (argument `a`), input grid, Rust reference and max relative error allowed.
const TANK_FUNCS: [(&str, Grid, TankFn, f64); 16] = [
    ("tank_radius()", Grid::None, |t, _| t.radius_m(), 1e-7),
    ("tank_height()", Grid::None, |t, _| t.height_m(), 1e-7),
    ("tank_volume()", Grid::None, |t, _| t.volume_m3(), 1e-7),
    (
        "tank_wall_area()",
        Grid::None,
        |t, _| t.wall_area_m2(),
        1e-7,
    ),
    (
        "tank_liquid_volume(a)",
        Grid::Height,
        |t, z| t.liquid_volume_m3(z),
        1e-6,
    ),
    (
        "tank_liquid_height(a)",
        Grid::Volume,
        |t, v| t.liquid_height_m(v),
        1e-6,
    ),
    (
        "tank_surface_radius(a)",
        Grid::Height,
        |t, z| t.surface_radius_m(z),
        1e-6,
    ),
    (
        "tank_interface_area(a)",
        Grid::Height,
        |t, z| t.interface_area_m2(z),
        1e-6,
    ),
    (
        "tank_wetted_area(a)",
        Grid::Height,
        |t, z| t.wetted_area_m2(z),
        1e-6,
    ),
    (
        "tank_dry_area(a)",
        Grid::Height,
        |t, z| t.dry_area_m2(z),
        1e-6,
    ),
    (
        "tank_wetted_area_slope(a)",
        Grid::Height,
        |t, z| t.wetted_area_slope_m(z),
        1e-6,
    ),
    (
        "tank_cross_section_area(a)",
        Grid::Height,
        |t, z| t.cross_section_area_m2(z),
        1e-6,
    ),
    (
        "tank_slosh_modes(a, tank_liquid_volume(a)).x",
        Grid::Height,
        |t, z| modes(t, z)[0].omega2_ratio,
        SLOSH_TOL,
    ),
    (
        "tank_slosh_modes(a, tank_liquid_volume(a)).y",
        Grid::Height,
        |t, z| modes(t, z)[0].mass_ratio,
        SLOSH_TOL,
    ),
    (
        "tank_slosh_modes(a, tank_liquid_volume(a)).z",
        Grid::Height,
        |t, z| modes(t, z)[1].omega2_ratio,
        SLOSH_TOL,
    ),
    (
        "tank_slosh_modes(a, tank_liquid_volume(a)).w",
        Grid::Height,
        |t, z| modes(t, z)[1].mass_ratio,
        SLOSH_TOL,
    ),
];

/// Tolerance of the slosh modes: f32 interpolation of the f32-rounded table, and the level of a
/// region boundary (bottom dome, barrel, top dome) falling on either side in f32.
const SLOSH_TOL: f64 = 1e-4;

/// The Rust slosh modes of `t` with the surface at `z` (m) over the liquid below it.
fn modes(t: &Tank, z: f64) -> [ModeShape; 2] {
    tank_modes(&TankLanes::<f64>::gather(|_| t), z, t.liquid_volume_m3(z))
}

/// The tanks under test with their dome heights `a = k R` (m): one of each shape and a
/// prolate capsule (the `asin` branch of the zone area), and a short-barrel 2:1 capsule (the slosh
/// tables between their barrel-length nodes).
fn tanks() -> Vec<(Tank, f64)> {
    vec![
        (Tank::new(Shape::Capsule, 2.0, 6.0, 0.707), 0.707 * 2.0),
        (Tank::new(Shape::Sphere, 1.5, 0.0, 1.0), 1.5),
        (Tank::new(Shape::Cylinder, 1.0, 3.0, 1.0), 0.0),
        (Tank::new(Shape::Capsule, 0.8, 2.0, 1.8), 1.8 * 0.8),
        (Tank::new(Shape::Capsule, 1.2, 0.5, 0.5), 0.5 * 1.2),
    ]
}

/// Liquid temperatures (K): 200 interior points and four outside the range on each side
/// (not so far out that `ln P_sat` leaves the f32 exponent range).
fn liquid_t(f: &FluidProps) -> Vec<f64> {
    let (lo, hi) = (f.t_min_k, f.t_max_k);
    let mut v: Vec<f64> = (0..200)
        .map(|i| lo + (hi - lo) * (i as f64 + 0.5) / 200.0)
        .collect();
    v.extend([lo + 1e-4, hi - 1e-4, lo - 2.0, 0.5 * lo, hi + 2.0, 1.5 * hi]);
    v
}

/// Input grid of a fluid function, rounded to f32 (the Rust reference uses the same values).
fn fluid_grid(grid: Grid, f: &FluidProps) -> Vec<f32> {
    let v: Vec<f64> = match grid {
        Grid::LiquidT => liquid_t(f),
        Grid::GasT => {
            let mut v: Vec<f64> = (0..=120).map(|i| 10f64.powf(i as f64 / 30.0)).collect();
            v.extend([0.0, 0.5, 2e4]);
            v
        }
        Grid::Pressure => {
            let (p_lo, p_hi) = (f.psat_pa(f.t_min_k), f.psat_pa(f.t_max_k));
            let mut v: Vec<f64> = liquid_t(f)[..200].iter().map(|&t| f.psat_pa(t)).collect();
            v.extend([0.5 * p_lo, 2.0 * p_hi, 0.0, -1e5]);
            v
        }
        Grid::Enthalpy => {
            let mut v: Vec<f64> = liquid_t(f).iter().map(|&t| f.h_l_j_per_kg(t)).collect();
            v.push(0.0);
            v
        }
        Grid::None => vec![0.0],
        Grid::Height | Grid::Volume => unreachable!("not a fluid grid"),
    };
    v.into_iter().map(|x| x as f32).collect()
}

/// Input grid of a tank function (dome height `dome`), rounded to f32.
fn tank_grid(grid: Grid, t: &Tank, dome: f64) -> Vec<f32> {
    let h = t.height_m();
    let mut z: Vec<f64> = (0..=300).map(|i| h * i as f64 / 300.0).collect();
    for r in [1e-7, 1e-6, 1e-4, 1e-2] {
        z.extend([r * h, h * (1.0 - r), dome * (1.0 + r), dome * (1.0 - r)]);
        z.extend([h - dome * (1.0 + r), h - dome * (1.0 - r)]);
    }
    z.extend([dome, h - dome, -1.0, h + 1.0]);
    let v: Vec<f64> = match grid {
        Grid::Height => z,
        Grid::Volume => {
            let vol = t.volume_m3();
            let mut v: Vec<f64> = z.iter().map(|&z| t.liquid_volume_m3(z)).collect();
            v.extend([-1.0, vol + 1.0, vol * (1.0 - 1e-6), vol * 1e-6]);
            v
        }
        Grid::None => vec![0.0],
        _ => unreachable!("not a tank grid"),
    };
    v.into_iter().map(|x| x as f32).collect()
}

/// The test kernel: `props_wgsl()`, the `Case` struct and an entry point that evaluates
/// case `i` into `out[i]` (one `switch` arm per entry of `FLUID_FUNCS` then `TANK_FUNCS`).
fn kernel() -> String {
    let mut arms = String::new();
    for (i, call) in FLUID_FUNCS
        .iter()
        .map(|f| f.0)
        .chain(TANK_FUNCS.iter().map(|f| f.0))
        .enumerate()
    {
        arms += &format!("        case {i}u: {{ r = {call}; }}\n");
    }
    format!(
        "{props}{case}
@group(0) @binding(0) var<storage, read> cases: array<Case>;
@group(0) @binding(1) var<storage, read> fluids: array<GpuFluid>;
@group(0) @binding(2) var<storage, read> tanks: array<GpuTank>;
@group(0) @binding(3) var<storage, read> gas: GpuGas;
@group(0) @binding(4) var<storage, read> tables: array<f32>;
@group(0) @binding(5) var<storage, read_write> out: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {{
    let i = id.x;
    if i >= arrayLength(&cases) {{
        return;
    }}
    let c = cases[i];
    HE = gas;
    if c.func < {nf}u {{
        FL = fluids[c.obj];
    }} else {{
        TANK = tanks[c.obj];
    }}
    let a = c.arg;
    var r = 0.0;
    switch c.func {{
{arms}        default: {{}}
    }}
    out[i] = r;
}}
",
        props = props_wgsl(),
        case = Case::wgsl(),
        nf = FLUID_FUNCS.len(),
    )
}

/// Runs `cases` through the kernel and returns one f32 per case.
fn run(
    gpu: (&wgpu::Device, &wgpu::Queue),
    cases: &[Case],
    fluids: &[GpuFluid],
    tanks: &[GpuTank],
) -> Vec<f32> {
    let gas = GpuGas::new(&HELIUM);
    let slosh_table = slosh_table_f32();
    let inputs: [&[u8]; 5] = [
        bytemuck::cast_slice(cases),
        bytemuck::cast_slice(fluids),
        bytemuck::cast_slice(tanks),
        bytemuck::bytes_of(&gas),
        bytemuck::cast_slice(&slosh_table),
    ];
    common::gpu::dispatch(
        gpu,
        "gpu_props",
        &kernel(),
        &inputs,
        cases.len(),
        cases.len(),
    )
}

/// One case's expectation: function index, fluid or tank label, f32 input, Rust f64 value.
struct Reference {
    func: usize,
    obj: String,
    arg: f32,
    rust: f64,
}

/// Relative error of `gpu` against `rust`; against a zero reference, `|gpu|` relative to
/// `scale` (the largest reference magnitude of that function on that fluid or tank).
fn rel_err(gpu: f32, rust: f64, scale: f64) -> f64 {
    let g = f64::from(gpu);
    if rust == 0.0 {
        g.abs() / scale.max(f64::MIN_POSITIVE)
    } else {
        (g - rust).abs() / rust.abs()
    }
}

#[test]
fn wgsl_props_match_rust() {
    let Some((device, queue, adapter)) = common::gpu::device_or_skip() else {
        return;
    };
    println!("adapter: {adapter}");
    let fluids: Vec<GpuFluid> = Fluid::ALL
        .iter()
        .map(|f| GpuFluid::new(f.props()))
        .collect();
    let tanks = tanks();
    let gpu_tanks: Vec<GpuTank> = tanks.iter().map(|(t, _)| GpuTank::new(t)).collect();

    let mut cases = Vec::new();
    let mut refs: Vec<Reference> = Vec::new();
    for (fi, &(_, grid, rust, _)) in FLUID_FUNCS.iter().enumerate() {
        for (oi, fluid) in Fluid::ALL.iter().enumerate() {
            for arg in fluid_grid(grid, fluid.props()) {
                cases.push(Case {
                    func: fi as u32,
                    obj: oi as u32,
                    arg,
                });
                refs.push(Reference {
                    func: fi,
                    obj: fluid.name().into(),
                    arg,
                    rust: rust(fluid.props(), f64::from(arg)),
                });
            }
        }
    }
    for (ti, &(_, grid, rust, _)) in TANK_FUNCS.iter().enumerate() {
        let fi = FLUID_FUNCS.len() + ti;
        for (oi, (tank, dome)) in tanks.iter().enumerate() {
            for arg in tank_grid(grid, tank, *dome) {
                cases.push(Case {
                    func: fi as u32,
                    obj: oi as u32,
                    arg,
                });
                let label = format!("{} #{oi}", tank.shape().name());
                refs.push(Reference {
                    func: fi,
                    obj: label,
                    arg,
                    rust: rust(tank, f64::from(arg)),
                });
            }
        }
    }
    let out = run((&device, &queue), &cases, &fluids, &gpu_tanks);
    assert_eq!(out.len(), refs.len());

    let names: Vec<&str> = FLUID_FUNCS
        .iter()
        .map(|f| f.0)
        .chain(TANK_FUNCS.iter().map(|f| f.0))
        .collect();
    let tols: Vec<f64> = FLUID_FUNCS
        .iter()
        .map(|f| f.3)
        .chain(TANK_FUNCS.iter().map(|f| f.3))
        .collect();
    let mut failures = Vec::new();
    for (fi, name) in names.iter().enumerate() {
        let rows: Vec<(&Reference, f32)> = refs
            .iter()
            .zip(&out)
            .filter(|(r, _)| r.func == fi)
            .map(|(r, &g)| (r, g))
            .collect();
        let mut worst = (0.0_f64, String::new(), 0.0_f32, 0.0_f64, 0.0_f32);
        for &(r, g) in &rows {
            let scale = rows
                .iter()
                .filter(|(s, _)| s.obj == r.obj)
                .map(|(s, _)| s.rust.abs())
                .fold(0.0, f64::max);
            // A NaN result counts as an infinite error.
            let e = rel_err(g, r.rust, scale);
            let e = if e.is_nan() { f64::INFINITY } else { e };
            if e >= worst.0 {
                worst = (e, r.obj.clone(), r.arg, r.rust, g);
            }
        }
        let (e, obj, arg, rust, gpu) = worst;
        println!(
            "{name:28} max rel err {e:9.2e} (tol {:.0e}) at {obj} arg {arg:e}: rust {rust:e} gpu {gpu:e}",
            tols[fi]
        );
        if e > tols[fi] {
            failures.push(*name);
        }
    }
    assert!(failures.is_empty(), "over tolerance: {failures:?}");
}
