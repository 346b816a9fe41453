//! `shaders/insulation.wgsl` against `model::insulation` (issue 17): one compute dispatch
//! evaluates the steady insulation leak and the MLI flux on a grid of stacks, surroundings and
//! wall temperatures in f32, each compared with the f64 Rust value at the same inputs. The
//! pattern of `tests/gpu_props.rs`, in a file of its own. Skipped (with a message) when there is
//! no GPU adapter, unless `CRYOSLOSH_REQUIRE_GPU=1`.

mod common;

use cryoslosh::gpu_struct;

gpu_struct! {
    /// One insulation evaluation: the stack (foam L/k, blanket coefficients, whether there is
    /// a blanket), the surroundings and the wall temperature (`model::insulation::leak`).
    pub struct InsCase {
        pub has_mli: u32,
        pub r_foam: f32,
        pub solid: f32,
        pub radiation: f32,
        pub gas: f32,
        pub h: f32,
        pub t_air: f32,
        pub t_rad4: f32,
        pub absorbed: f32,
        pub eps_sigma: f32,
        pub t_wall: f32,
    }
}

/// `shaders/insulation.wgsl` against `model::insulation` in f64 at the same f32 inputs: the
/// MLI flux (modified Lockheed) and the steady leak through foam, blanket or both, ground and
/// space, over wall temperatures 20–300 K. The solve takes the same number of Newton steps on
/// both; f32 leaves ~1e-6 of the flux. Skipped without an adapter unless
/// `CRYOSLOSH_REQUIRE_GPU=1`.
#[test]
fn wgsl_insulation_matches_rust() {
    use cryoslosh::model::insulation::{
        leak, mli_flux, Foam, Mli, MliCoefficients, Stack, Surroundings, STEFAN_BOLTZMANN,
    };
    let Some((device, queue, adapter)) = common::gpu::device_or_skip() else {
        return;
    };
    println!("adapter: {adapter}");
    let blankets = [
        Some(Mli {
            layers: 30.0,
            layer_density_per_cm: 15.0,
            interstitial_pressure_torr: 1.0e-5,
            shield_emissivity: 0.031,
            degradation_factor: 1.5,
        }),
        Some(Mli {
            layers: 5.0,
            layer_density_per_cm: 2.0,
            interstitial_pressure_torr: 1.0e-3,
            shield_emissivity: 0.05,
            degradation_factor: 1.0,
        }),
        None,
    ];
    let foams = [
        None,
        Some(Foam {
            thickness_m: 0.03,
            conductivity_w_per_m_k: 0.02,
        }),
    ];
    let envs = [
        (5.0, 293.15, 0.0, 0.9),
        (0.0, 2.725, 80.0, 0.9),
        (0.0, 2.725, 0.0, 0.05),
        (50.0, 350.0, 0.0, 1.0),
    ];
    let mut cases = Vec::new();
    for m in blankets {
        for foam in foams {
            if m.is_none() && foam.is_none() {
                continue;
            }
            for (h, t, absorbed, eps) in envs {
                for t_wall in [20.0_f32, 90.0, 150.0, 300.0] {
                    let k = m.map(|m| m.coefficients()).unwrap_or(MliCoefficients {
                        solid: 0.0,
                        radiation: 0.0,
                        gas: 0.0,
                    });
                    let t = t as f32;
                    cases.push(InsCase {
                        has_mli: u32::from(m.is_some()),
                        r_foam: foam.map_or(0.0, |f| f.resistance_m2_k_per_w()) as f32,
                        solid: k.solid as f32,
                        radiation: k.radiation as f32,
                        gas: k.gas as f32,
                        h: h as f32,
                        t_air: t,
                        t_rad4: t * t * (t * t),
                        absorbed: absorbed as f32,
                        eps_sigma: (eps * STEFAN_BOLTZMANN) as f32,
                        t_wall,
                    });
                }
            }
        }
    }
    let source = format!(
        "{consts}{ins}{case}
@group(0) @binding(0) var<storage, read> cases: array<InsCase>;
@group(0) @binding(1) var<storage, read_write> out: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {{
    let i = id.x;
    if i >= arrayLength(&cases) {{
        return;
    }}
    let c = cases[i];
    var k: MliCoeffs;
    k.solid = c.solid;
    k.radiation = c.radiation;
    k.gas = c.gas;
    var e: Surroundings;
    e.h = c.h;
    e.t_air = c.t_air;
    e.t_rad4 = c.t_rad4;
    e.absorbed = c.absorbed;
    e.eps_sigma = c.eps_sigma;
    let l = insulation_leak(c.has_mli != 0u, c.r_foam, k, e, c.t_wall);
    out[3u * i] = l.q;
    out[3u * i + 1u] = l.t_outer;
    out[3u * i + 2u] = mli_flux(k, 293.0, c.t_wall).x;
}}
",
        consts = cryoslosh::gpu::params::constants_wgsl(false),
        ins = include_str!("../shaders/insulation.wgsl"),
        case = InsCase::wgsl(),
    );
    let got = common::gpu::dispatch(
        (&device, &queue),
        "insulation",
        &source,
        &[bytemuck::cast_slice(&cases)],
        3 * cases.len(),
        cases.len(),
    );

    let (mut worst_q, mut worst_t, mut worst_mli) = (0.0_f64, 0.0_f64, 0.0_f64);
    let mut worst_case = String::new();
    for (i, c) in cases.iter().enumerate() {
        let f = f64::from;
        let k = MliCoefficients {
            solid: f(c.solid),
            radiation: f(c.radiation),
            gas: f(c.gas),
        };
        let stack = Stack {
            foam_resistance_m2_k_per_w: f(c.r_foam),
            mli: (c.has_mli != 0).then_some(k),
        };
        let env = Surroundings {
            h_w_per_m2_k: f(c.h),
            t_air_k: f(c.t_air),
            t_rad4_k4: f(c.t_rad4),
            absorbed_w_per_m2: f(c.absorbed),
            eps_sigma: f(c.eps_sigma),
        };
        let rust = leak(&stack, &env, f(c.t_wall));
        // Relative to the flux, or to what 1e-6 K of outer temperature moves it by.
        let scale = rust.flux_w_per_m2.abs().max(1e-3);
        let eq = (f(got[3 * i]) - rust.flux_w_per_m2).abs() / scale;
        let et = (f(got[3 * i + 1]) - rust.t_outer_k).abs() / rust.t_outer_k;
        let eq = if eq.is_nan() { f64::INFINITY } else { eq };
        if eq > worst_q {
            worst_case = format!(
                "{c:?}: gpu {} W/m² at {} K, rust {} W/m² at {} K",
                got[3 * i],
                got[3 * i + 1],
                rust.flux_w_per_m2,
                rust.t_outer_k
            );
        }
        worst_q = worst_q.max(eq);
        worst_t = worst_t.max(if et.is_nan() { f64::INFINITY } else { et });
        if c.has_mli != 0 {
            let m = mli_flux(&k, 293.0, f(c.t_wall)).0;
            let em = (f(got[3 * i + 2]) - m).abs() / m.abs().max(1e-6);
            worst_mli = worst_mli.max(if em.is_nan() { f64::INFINITY } else { em });
        }
    }
    println!(
        "insulation: {} cases, max rel err: leak {worst_q:.2e}, outer temperature {worst_t:.2e}, MLI flux {worst_mli:.2e}",
        cases.len()
    );
    println!("largest leak difference: {worst_case}");
    assert!(worst_mli < 2e-5, "MLI flux {worst_mli:e}");
    assert!(worst_q < 1e-3, "leak {worst_q:e}");
    assert!(worst_t < 1e-5, "outer temperature {worst_t:e}");
}
