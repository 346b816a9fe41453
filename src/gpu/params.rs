//! What one GPU invocation reads and writes: the instance's parameters and phases in f32, its
//! initial state split into f32 hi + lo words, and its quantities of interest. Every constant the
//! kernel shares with the CPU model is emitted from the Rust definitions by
//! [`super::constants::constants_wgsl`] (re-exported here).

use crate::fluids::{Fluid, HELIUM};
use crate::gpu::props::{GpuFluid, GpuGas, GpuTank};
use crate::gpu_struct;
use crate::model::flight::{Excitation, Phase, PhaseKind};
use crate::model::params::{Fidelity, Params};
use crate::model::state::{State, NL_MAX};

/// The state slots the device records carry: all of them. A kernel's own state type covers
/// [`kernel_slots`] of them (the `layered` column's only in the kernel built for that level).
pub const DEVICE_SLOTS: usize = crate::model::state::NS;

/// The state slots a kernel carries in its registers: the leading `state::COL`, every level's,
/// and the `layered` column's enthalpies only in the kernel built for that level (`layered`).
pub fn kernel_slots(layered: bool) -> usize {
    if layered {
        crate::model::state::NS
    } else {
        crate::model::state::COL
    }
}

pub use super::constants::constants_wgsl;

/// Optional closures present in [`GpuParams::flags`].
pub mod flag {
    pub const EVAP_COEFF: u32 = 1;
    pub const H_US: u32 = 2;
    pub const H_SB: u32 = 4;
    pub const H_WALL_ULLAGE: u32 = 8;
    pub const H_WALL_LIQUID: u32 = 16;
    pub const PRESSURIZATION: u32 = 32;
    pub const RELIEF: u32 = 64;
    /// The pressurant is the propellant's own vapour (`PressurantGas::Autogenous`).
    pub const AUTOGENOUS: u32 = 128;
    /// `[insulation]` replaces the fixed heat leak (`shaders/insulation.wgsl`).
    pub const INSULATION: u32 = 256;
    /// The insulation has a multilayer blanket (else bare foam).
    pub const MLI: u32 = 512;
    /// `[mixer]`: a jet mixer exchanges layer and bulk liquid and heats it (`model::mixer`).
    pub const MIXER: u32 = 1024;
    /// `[tvs]`: a thermodynamic vent system holds the pressure in a band (`model::tvs`).
    pub const TVS: u32 = 2048;
}

/// Excitation kinds in [`GpuPhase::exc_kind`].
pub mod exc {
    pub const NONE: u32 = 0;
    pub const STEP: u32 = 1;
    pub const RAMP: u32 = 2;
    pub const SINE: u32 = 3;
    pub const SWEEP: u32 = 4;
    pub const GUST: u32 = 5;
    pub const TABLE: u32 = 6;
}

/// Why an instance diverged, in [`GpuResult::diverged`] (0: it did not).
pub const DIVERGED_REASONS: [&str; 15] = [
    "",
    "a state slot is not finite",
    "ullage pressure",
    "ullage volume",
    "ullage temperature",
    "layer temperature",
    "bulk temperature",
    "dry wall temperature",
    "wetted wall temperature",
    "vapour mass",
    "helium mass",
    "layer or bulk mass",
    "coldest liquid temperature",
    "warmest liquid temperature",
    "error-controlled step size (it fell below 1e-12 of the phase time)",
];

gpu_struct! {
    /// One instance's resolved inputs (MODEL.md symbols; see `model::params` for each unit).
    pub struct GpuParams {
        pub fidelity: u32,
        pub flags: u32,
        pub baffle_count: u32,
        pub n_phases: u32,
        pub tank: GpuTank,
        pub heat_leak_w: f32,
        /// `[insulation]` (`model::insulation`): foam L/k (m²·K/W), the blanket's solid,
        /// radiation and gas coefficients, ground convection (W/(m²·K)) and air temperature (K),
        /// space sink temperature (K) and absorbed flux (W/m²), outer ε σ (W/(m²·K⁴)).
        pub ins_foam_resistance: f32,
        pub ins_mli_solid: f32,
        pub ins_mli_radiation: f32,
        pub ins_mli_gas: f32,
        pub ins_ground_h: f32,
        pub ins_ground_t: f32,
        pub ins_space_t: f32,
        pub ins_space_absorbed: f32,
        pub ins_eps_sigma: f32,
        /// Surface tension fit σ_0 (N/m), exponent and T_c (K) (`fluids::surface_tension`).
        pub sigma0: f32,
        pub sigma_exp: f32,
        pub sigma_tc: f32,
        pub wall_areal_mass: f32,
        pub wall_cp: f32,
        pub evap_coeff: f32,
        pub accommodation: f32,
        pub h_us: f32,
        pub h_sb: f32,
        pub h_wall_ullage: f32,
        pub h_wall_liquid: f32,
        pub diffusivity_factor: f32,
        pub wall_heat_to_layer: f32,
        pub coupling_volume_m3: f32,
        pub coupling_h: f32,
        pub coupling_mixing: f32,
        pub baffle_width_m: f32,
        pub baffle_spacing_m: f32,
        pub baffle_top_m: f32,
        pub baffle_wave_m: f32,
        pub extra_damping: f32,
        pub press_setpoint_pa: f32,
        pub press_kp: f32,
        pub press_kd: f32,
        pub press_filter_s: f32,
        pub press_max_flow: f32,
        pub press_gas_t: f32,
        pub press_bottle_kg: f32,
        /// The gain schedule's reference ullage V_ref (m³; `GainSchedule::reference_or_zero_m3`):
        /// both gains times V_u / V_ref where it is positive, fixed where it is 0.
        pub press_schedule_ref_m3: f32,
        pub relief_crack_pa: f32,
        pub relief_reseat_pa: f32,
        pub relief_area_m2: f32,
        /// `[mixer]` (`model::mixer`): the exchange rate 1/τ = ln 20 / t_mix (1/s) and the pump
        /// heat (W), applied in phases whose `mixer` is set.
        pub mixer_rate_per_s: f32,
        pub mixer_heat_w: f32,
        /// `[tvs]` (`model::tvs`): the band (Pa), the J-T flow (kg/s), the J-T outlet's
        /// saturation temperature (K) and vapour enthalpy (J/kg), the spray pump's flow (m³/s)
        /// and heat (W).
        pub tvs_upper_pa: f32,
        pub tvs_lower_pa: f32,
        pub tvs_flow_kg_s: f32,
        pub tvs_t_jt_k: f32,
        pub tvs_h_vent: f32,
        pub tvs_pump_m3_s: f32,
        pub tvs_pump_heat_w: f32,
        pub isp_s: f32,
        pub propellant_fraction: f32,
        pub line_height_m: f32,
        pub line_loss_pa: f32,
        pub line_velocity_m_s: f32,
        pub npsh_required_m: f32,
        pub dry_mass_kg: f32,
        pub drag_area_m2: f32,
        pub lever_arm_m: f32,
        /// `[layered]` (`model::column`): the number of layers, the boundary layer's detrainment
        /// width (K) and the layers' mass fractions w_k, bottom to top (0 from `layers` on).
        pub layers: u32,
        pub detrain_width_k: f32,
        pub layer_w: [f32; NL_MAX],
        pub s0_hi: [f32; DEVICE_SLOTS],
        pub s0_lo: [f32; DEVICE_SLOTS],
        /// Error control (`campaign.rtol`; `campaign.atol` times each slot's reference scale,
        /// `simulate::adaptive::reference_scales`).
        pub rtol: f32,
        pub atol: [f32; DEVICE_SLOTS],
    }
}

gpu_struct! {
    /// One phase of one instance: steps, drive and excitation.
    pub struct GpuPhase {
        pub kind: u32,
        pub n_steps: u32,
        pub pressurize: u32,
        /// The insulation faces space (`flight::Environment::Space`), else the ground.
        pub space: u32,
        /// The jet mixer runs in this phase (`flight::Phase::mixer`; with `[mixer]` only).
        pub mixer: u32,
        /// The TVS may run in this phase (`flight::Phase::tvs`; with `[tvs]` only).
        pub tvs: u32,
        pub exc_kind: u32,
        pub table_start: u32,
        pub table_len: u32,
        pub dt: f32,
        pub thrust_n: f32,
        pub gamma_rad: f32,
        pub gravity: f32,
        pub exc: [f32; 4],
        /// Error-controlled stepping (`simulate::adaptive`): the phase's duration and first
        /// step (s), its step bound, the excitation period (0: none) and the phase-time window
        /// in which it bounds the step (a gust's), the excitation corners (3.4e38: none) and
        /// whether the phase excites the liquid at all.
        pub duration_s: f32,
        pub first_step_s: f32,
        pub max_step_s: f32,
        pub exc_period_s: f32,
        pub period_from_s: f32,
        pub period_to_s: f32,
        pub corner0_s: f32,
        pub corner1_s: f32,
        pub excites: u32,
    }
}

gpu_struct! {
    /// One instance's integration carried from dispatch to dispatch (where it is, its state in
    /// hi + lo words, the derivative to reuse) and its quantities of interest so far.
    pub struct GpuResult {
        pub started: u32,
        pub done: u32,
        pub phase: u32,
        pub step_in_phase: u32,
        pub valve_open: u32,
        /// The thermodynamic vent system runs (`model::tvs`).
        pub tvs_on: u32,
        pub have_k1: u32,
        pub phase_start_s: f32,
        pub steps: u32,
        pub diverged: u32,
        pub diverged_phase: u32,
        pub drew: u32,
        pub diverged_value: f32,
        pub diverged_time_s: f32,
        pub peak_pressure_pa: f32,
        pub peak_pressure_time_s: f32,
        pub min_pressure_pa: f32,
        pub min_pressure_time_s: f32,
        pub min_margin_m: f32,
        pub min_margin_pa: f32,
        pub min_margin_time_s: f32,
        pub max_slosh_angle_rad: f32,
        pub peak_slosh_force_n: f32,
        pub peak_slosh_moment_n_m: f32,
        pub final_time_s: f32,
        pub m_vapor0_kg: f32,
        /// Liquid mass at the start and after the last step, kg (depletion).
        pub m_liquid0_kg: f32,
        pub m_liquid_kg: f32,
        /// Relief-valve openings; pressurant exhausted and tank dry, with their times.
        pub relief_cycles: u32,
        /// Thermodynamic-vent-system starts.
        pub tvs_cycles: u32,
        /// |slosh angle| at the last observation, rad (a phase entered there starts with it).
        pub last_angle_rad: f32,
        /// Error-controlled stepping: the next step's proposal and the time within the phase
        /// (s), rejected attempts, right-hand-side evaluations, the evaporation rate (kg/s) and
        /// highest slosh frequency (rad/s) at the last accepted state, and the extreme-seeking
        /// quantities there (pressure, −pressure, −margin, |angle|, |force|).
        pub h_s: f32,
        pub t_phase_s: f32,
        pub rejected: u32,
        pub evaluations: u32,
        pub evap_last: f32,
        pub omega_last: f32,
        pub q_last: [f32; 5],
        /// The slosh analog left its range (flag) and for how long, s.
        pub slosh_out: u32,
        pub slosh_out_time_s: f32,
        pub exhausted: u32,
        pub exhausted_time_s: f32,
        pub depleted: u32,
        pub depleted_time_s: f32,
        pub m_vapor_kg: f32,
        pub t_layer_k: f32,
        pub t_bulk_k: f32,
        pub p_ullage_pa: f32,
        pub s_hi: [f32; DEVICE_SLOTS],
        pub s_lo: [f32; DEVICE_SLOTS],
        pub k1: [f32; DEVICE_SLOTS],
    }
}

gpu_struct! {
    /// One phase of one instance as the kernel saw it (`simulate::PhaseSummary`): whether it was
    /// entered, its start values (pressure; vapour mass, vented, pressurant and TVS-vented slots
    /// in hi + lo words) and its extremes. Indexed like the phases, instance × phase.
    pub struct GpuPhaseResult {
        pub entered: u32,
        pub drew: u32,
        pub start_pressure_pa: f32,
        pub peak_pressure_pa: f32,
        pub min_pressure_pa: f32,
        pub min_margin_m: f32,
        pub max_slosh_angle_rad: f32,
        pub m_vapor_hi: f32,
        pub m_vapor_lo: f32,
        pub vent_v_hi: f32,
        pub vent_v_lo: f32,
        pub vent_g_hi: f32,
        pub vent_g_lo: f32,
        /// Pressurant admitted at the phase start (autogenous vapour is not boil-off), kg.
        pub press_in_hi: f32,
        pub press_in_lo: f32,
        /// Bulk liquid the TVS had vented at the phase start, kg.
        pub vent_tvs_hi: f32,
        pub vent_tvs_lo: f32,
    }
}

gpu_struct! {
    /// What every invocation of one dispatch shares.
    pub struct GpuControl {
        /// Steps each instance may advance in this dispatch.
        pub step_budget: u32,
        /// 1.0, unknown to the shader compiler: multiplying by it keeps Kahan's `(s − hi)` from
        /// being simplified to the increment (NIR and others fold `(a + b) − a` → `b`).
        pub one: f32,
    }
}

/// f64 → f32 high word and the f32 remainder, so that hi + lo carries ~48 bits.
pub fn split(v: f64) -> (f32, f32) {
    let hi = v as f32;
    (hi, (v - f64::from(hi)) as f32)
}

/// hi + lo in f64.
pub fn join(hi: f32, lo: f32) -> f64 {
    f64::from(hi) + f64::from(lo)
}

pub(super) fn fidelity_code(f: Fidelity) -> u32 {
    match f {
        Fidelity::Homogeneous => 0,
        Fidelity::Lumped => 1,
        Fidelity::TwoMode => 2,
        Fidelity::Layered => 3,
    }
}

impl GpuParams {
    /// Parameters of an instance with parameters `p`, `n_phases` phases, initial state `s0` and
    /// error-control tolerances `(rtol, atol)` (`campaign.rtol`, `campaign.atol`).
    pub fn new(p: &Params, n_phases: usize, s0: &State, (rtol, atol): (f64, f64)) -> GpuParams {
        let ht = &p.heat_transfer;
        let mut flags = 0;
        let mut opt = |v: Option<f64>, bit: u32| {
            if v.is_some() {
                flags |= bit;
            }
            v.unwrap_or(0.0) as f32
        };
        let evap_coeff = opt(ht.evaporation_coefficient_kg_per_s_pa, flag::EVAP_COEFF);
        let h_us = opt(ht.h_us_w_per_m2_k, flag::H_US);
        let h_sb = opt(ht.h_sb_w_per_m2_k, flag::H_SB);
        let h_wall_ullage = opt(ht.h_wall_ullage_w_per_m2_k, flag::H_WALL_ULLAGE);
        let h_wall_liquid = opt(ht.h_wall_liquid_w_per_m2_k, flag::H_WALL_LIQUID);
        let ps = p.pressurization;
        let rl = p.relief;
        if ps.is_some() {
            flags |= flag::PRESSURIZATION;
        }
        if p.pressurant_vapor_share() > 0.0 {
            flags |= flag::AUTOGENOUS;
        }
        if rl.is_some() {
            flags |= flag::RELIEF;
        }
        if p.mixer.is_some() {
            flags |= flag::MIXER;
        }
        if p.tvs.is_some() {
            flags |= flag::TVS;
        }
        let tvf = |g: fn(&crate::model::tvs::Tvs) -> f64| p.tvs.map_or(0.0, |t| g(&t)) as f32;
        let ins = p.insulation;
        if let Some(i) = ins {
            flags |= flag::INSULATION;
            if i.mli.is_some() {
                flags |= flag::MLI;
            }
        }
        let stack = ins.map(|i| i.stack());
        let mli = stack.and_then(|s| s.mli);
        let ground = ins.map(|i| i.surroundings(crate::model::flight::Environment::Ground));
        let space = ins.map(|i| i.surroundings(crate::model::flight::Environment::Space));
        let f = |v: f64| v as f32;
        let psf =
            |g: fn(&crate::model::params::Pressurization) -> f64| ps.as_ref().map_or(0.0, g) as f32;
        let rlf = |g: fn(&crate::model::params::Relief) -> f64| rl.as_ref().map_or(0.0, g) as f32;
        let mut s0_hi = [0.0; DEVICE_SLOTS];
        let mut s0_lo = [0.0; DEVICE_SLOTS];
        for i in 0..DEVICE_SLOTS {
            (s0_hi[i], s0_lo[i]) = split(s0[i]);
        }
        GpuParams {
            fidelity: fidelity_code(p.fidelity),
            flags,
            baffle_count: p.baffles.count,
            n_phases: n_phases as u32,
            tank: GpuTank::new(&p.tank),
            heat_leak_w: f(p.heat_leak_w),
            ins_foam_resistance: f(stack.map_or(0.0, |s| s.foam_resistance_m2_k_per_w)),
            ins_mli_solid: f(mli.map_or(0.0, |m| m.solid)),
            ins_mli_radiation: f(mli.map_or(0.0, |m| m.radiation)),
            ins_mli_gas: f(mli.map_or(0.0, |m| m.gas)),
            ins_ground_h: f(ground.map_or(0.0, |g| g.h_w_per_m2_k)),
            ins_ground_t: f(ground.map_or(0.0, |g| g.t_air_k)),
            ins_space_t: f(space.map_or(0.0, |g| g.t_air_k)),
            ins_space_absorbed: f(space.map_or(0.0, |g| g.absorbed_w_per_m2)),
            ins_eps_sigma: f(space.map_or(0.0, |g| g.eps_sigma)),
            sigma0: f(p.fluid.surface_tension().sigma0_n_per_m),
            sigma_exp: f(p.fluid.surface_tension().exponent),
            sigma_tc: f(p.fluid.surface_tension().t_crit_k),
            wall_areal_mass: f(p.wall_areal_mass_kg_per_m2),
            wall_cp: f(p.wall_cp_j_per_kg_k),
            evap_coeff,
            accommodation: f(ht.accommodation),
            h_us,
            h_sb,
            h_wall_ullage,
            h_wall_liquid,
            diffusivity_factor: f(p.stratification.diffusivity_factor),
            wall_heat_to_layer: f(p.stratification.wall_heat_to_layer),
            coupling_volume_m3: f(p.coupling.volume_m3),
            coupling_h: f(p.coupling.h_enhancement_w_per_m2_k_s),
            coupling_mixing: f(p.coupling.mixing),
            baffle_width_m: f(p.baffles.width_m),
            baffle_spacing_m: f(p.baffles.spacing_m),
            baffle_top_m: f(p.baffles.top_height_m),
            baffle_wave_m: f(p.baffles.wave_amplitude_m),
            extra_damping: f(p.extra_damping),
            press_setpoint_pa: psf(|x| x.setpoint_pa),
            press_kp: psf(|x| x.kp_kg_per_s_pa),
            press_kd: psf(|x| x.kd_kg_per_pa),
            press_filter_s: psf(|x| x.derivative_filter_s),
            press_max_flow: psf(|x| x.max_flow_kg_per_s),
            press_gas_t: psf(|x| x.gas_temperature_k),
            press_bottle_kg: psf(|x| x.bottle_mass_kg),
            press_schedule_ref_m3: psf(|x| x.gain_schedule.reference_or_zero_m3()),
            relief_crack_pa: rlf(|x| x.crack_pa),
            relief_reseat_pa: rlf(|x| x.reseat_pa),
            relief_area_m2: rlf(|x| x.flow_area_m2),
            mixer_rate_per_s: f(crate::model::mixer::exchange_rate_per_s(p)),
            mixer_heat_w: f(crate::model::mixer::pump_heat_w(p)),
            tvs_upper_pa: tvf(|t| t.band_upper_pa),
            tvs_lower_pa: tvf(|t| t.band_lower_pa),
            tvs_flow_kg_s: tvf(|t| t.jt_flow_kg_s),
            tvs_t_jt_k: tvf(|t| t.jt_temperature_k),
            tvs_h_vent: tvf(|t| t.vent_enthalpy_j_per_kg),
            tvs_pump_m3_s: tvf(|t| t.pump_flow_m3_s),
            tvs_pump_heat_w: tvf(|t| t.pump_heat_w),
            isp_s: f(p.feed.isp_s),
            propellant_fraction: f(p.feed.propellant_fraction),
            line_height_m: f(p.feed.line_height_m),
            line_loss_pa: f(p.feed.line_loss_pa),
            line_velocity_m_s: f(p.feed.line_velocity_m_s),
            npsh_required_m: f(p.feed.npsh_required_m),
            dry_mass_kg: f(p.vehicle.dry_mass_kg),
            drag_area_m2: f(p.vehicle.drag_area_m2),
            lever_arm_m: f(p.vehicle.slosh_lever_arm_m),
            layers: p.layered.layers.clamp(1, NL_MAX as u32),
            detrain_width_k: f(p.layered.detrain_width_k),
            layer_w: crate::model::column::fractions(&p.layered).map(|w| w as f32),
            s0_hi,
            s0_lo,
            rtol: rtol as f32,
            atol: {
                let scales = crate::simulate::adaptive::reference_scales(p, s0);
                std::array::from_fn(|i| (scales[i] * atol) as f32)
            },
        }
    }
}

/// Excitation tables of one upload as rows (t, a_lat, a_ax): each distinct table is stored once
/// however many instances' phases use it (tables are read from a file, rarely dispersed). The
/// buffer starts with the slosh tables ([`crate::gpu::props::slosh_table_f32`], whole rows),
/// which `shaders/slosh_modes.wgsl` reads from index 0.
pub struct Tables {
    /// The rows, flattened: the slosh tables, then the excitation rows.
    pub rows: Vec<f32>,
    /// Tables stored so far and their first row.
    stored: Vec<(Excitation, u32)>,
}

impl Default for Tables {
    fn default() -> Tables {
        Tables {
            rows: crate::gpu::props::slosh_table_f32(),
            stored: Vec::new(),
        }
    }
}

impl Tables {
    /// First row and row count of table excitation `e` (`time_s`, `a_lat`, `a_ax`), stored once.
    fn place(&mut self, e: &Excitation, time_s: &[f64], a_lat: &[f64], a_ax: &[f64]) -> (u32, u32) {
        let len = time_s.len() as u32;
        if let Some((_, start)) = self.stored.iter().find(|(x, _)| x == e) {
            return (*start, len);
        }
        let start = (self.rows.len() / 3) as u32;
        for ((t, l), x) in time_s.iter().zip(a_lat).zip(a_ax) {
            self.rows.extend([*t as f32, *l as f32, *x as f32]);
        }
        self.stored.push((e.clone(), start));
        (start, len)
    }
}

pub(super) fn phase_code(k: PhaseKind) -> u32 {
    match k {
        PhaseKind::Hold => 0,
        PhaseKind::Burn => 1,
        PhaseKind::Coast => 2,
    }
}

impl GpuPhase {
    /// The phase in f32; a table excitation's rows go to `tables`.
    pub fn new(ph: &Phase, tables: &mut Tables) -> GpuPhase {
        let (n, dt) = ph.steps();
        let (mut table_start, mut table_len) = (0, 0);
        let (exc_kind, e) = match &ph.excitation {
            Excitation::None => (exc::NONE, [0.0; 4]),
            Excitation::Step { amplitude, start_s } => {
                (exc::STEP, [*amplitude, *start_s, 0.0, 0.0])
            }
            Excitation::Ramp {
                amplitude,
                start_s,
                duration_s,
            } => (exc::RAMP, [*amplitude, *start_s, *duration_s, 0.0]),
            Excitation::Sine {
                amplitude,
                frequency_hz,
                phase_rad,
            } => (exc::SINE, [*amplitude, *frequency_hz, *phase_rad, 0.0]),
            Excitation::Sweep {
                amplitude,
                f_start_hz,
                f_end_hz,
                duration_s,
            } => (
                exc::SWEEP,
                [*amplitude, *f_start_hz, *f_end_hz, *duration_s],
            ),
            Excitation::Gust {
                amplitude,
                start_s,
                duration_s,
            } => (exc::GUST, [*amplitude, *start_s, *duration_s, 0.0]),
            Excitation::Table {
                time_s,
                a_lat,
                a_ax,
            } => {
                (table_start, table_len) = tables.place(&ph.excitation, time_s, a_lat, a_ax);
                (exc::TABLE, [0.0; 4])
            }
        };
        let (period_from, period_to) = match ph.excitation {
            Excitation::Gust {
                start_s,
                duration_s,
                ..
            } => (start_s, start_s + duration_s),
            _ => (f64::MIN, f64::MAX),
        };
        let [corner0, corner1] = ph.breakpoints().map(|b| b.min(f64::from(f32::MAX)));
        GpuPhase {
            duration_s: ph.duration_s as f32,
            first_step_s: ph.dt_s as f32,
            max_step_s: ph.max_step_s as f32,
            exc_period_s: ph.excitation_period_s().unwrap_or(0.0) as f32,
            period_from_s: period_from.max(f64::from(f32::MIN)) as f32,
            period_to_s: period_to.min(f64::from(f32::MAX)) as f32,
            corner0_s: corner0 as f32,
            corner1_s: corner1 as f32,
            excites: u32::from(ph.excitation != Excitation::None),
            kind: phase_code(ph.kind),
            n_steps: n as u32,
            pressurize: u32::from(ph.pressurize),
            space: u32::from(ph.environment == crate::model::flight::Environment::Space),
            mixer: u32::from(ph.mixer),
            tvs: u32::from(ph.tvs),
            exc_kind,
            table_start,
            table_len,
            dt: dt as f32,
            thrust_n: ph.thrust_n as f32,
            gamma_rad: ph.flight_path_angle_rad as f32,
            gravity: ph.gravity_m_s2 as f32,
            exc: e.map(|v: f64| v as f32),
        }
    }
}

/// The campaign-wide fluid and helium records for `fluid`.
pub fn fluid_records(fluid: Fluid) -> (GpuFluid, GpuGas) {
    (GpuFluid::new(fluid.props()), GpuGas::new(&HELIUM))
}
