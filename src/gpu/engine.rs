//! The WGSL engine: instances are sampled and resolved on the CPU (rayon), uploaded as f32
//! records, integrated through their whole phase list by the WGSL kernel in `shaders/` (one instance per
//! invocation) and only the quantities of interest come back.
//!
//! Batches respect the adapter's storage-binding size and 65,535 workgroups per dimension.
//! Instances the kernel cannot take (a propellant other than the campaign's) run on the CPU.

use super::context::{Gpu, GpuError};
use super::params::{
    fluid_records, join, GpuControl, GpuParams, GpuPhase, GpuPhaseResult, GpuResult, Tables,
    DEVICE_SLOTS, DIVERGED_REASONS,
};
use super::props::{props_wgsl, GpuFluid, GpuGas};
use crate::campaign::Integrator;
use crate::engine::Engine;
use crate::model::derive::Derived;
use crate::model::flight::Phase;
use crate::model::params::{Fidelity, Params};
use crate::model::state::{State, M_V, NS, PRESS_IN, VENT_G, VENT_TVS, VENT_V};
use crate::montecarlo::plan::{InstanceRecord, Plan};
use crate::simulate::{cumulative, finish_summary, initial_state, PhaseSummary, Summary};
use rayon::prelude::*;
use std::ops::Range;
use wgpu::util::DeviceExt;

/// Invocations per workgroup (the kernel's `@workgroup_size`).
const WORKGROUP: u32 = 64;

/// The whole kernel source for `integrator`: generated constants and structs, the physics and
/// observation (`shaders/model.wgsl`, `derive.wgsl`, `insulation.wgsl`, `closures.wgsl`, `rhs.wgsl`,
/// `observe.wgsl`), then the stepping loop (`shaders/rk4.wgsl` with entry
/// point `main`, or `shaders/adaptive.wgsl` with `main_dopri5` and `adaptive_events.wgsl`).
/// One module per integrator: a driver that compiles the whole module for each entry point
/// (llvmpipe) pays for one loop only.
///
/// `layered`: the kernel that also runs the `layered` level, with `shaders/column.wgsl` and the
/// column's slots in its state type; the others leave out every block between `// LAYERED{` and
/// `// }LAYERED` lines, so that the lumped levels carry no column in their registers.
pub fn kernel_source(integrator: Integrator, layered: bool) -> String {
    let stepping = match integrator {
        Integrator::Rk4 => include_str!("../../shaders/rk4.wgsl").to_string(),
        Integrator::Dopri5 => [
            include_str!("../../shaders/adaptive.wgsl"),
            include_str!("../../shaders/adaptive_events.wgsl"),
        ]
        .join("\n"),
    };
    let column = if layered {
        include_str!("../../shaders/column.wgsl")
    } else {
        ""
    };
    let text = [
        super::params::constants_wgsl(layered),
        props_wgsl(),
        GpuParams::wgsl(),
        GpuPhase::wgsl(),
        GpuResult::wgsl(),
        GpuPhaseResult::wgsl(),
        GpuControl::wgsl(),
        include_str!("../../shaders/model.wgsl").to_string(),
        include_str!("../../shaders/derive.wgsl").to_string(),
        include_str!("../../shaders/insulation.wgsl").to_string(),
        include_str!("../../shaders/closures.wgsl").to_string(),
        include_str!("../../shaders/rhs.wgsl").to_string(),
        column.to_string(),
        include_str!("../../shaders/observe.wgsl").to_string(),
        stepping,
    ]
    .join("\n");
    if layered {
        return text;
    }
    let mut out = String::with_capacity(text.len());
    let mut inside = false;
    for line in text.lines() {
        let marker = line.trim_start();
        if marker.starts_with("// LAYERED{") {
            inside = true;
        } else if marker.starts_with("// }LAYERED") {
            inside = false;
        } else if !inside {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

/// A kernel compiled on first use, or why it failed.
type LazyKernel = std::sync::OnceLock<Result<wgpu::ComputePipeline, String>>;

/// Integrates instances with the WGSL kernel.
pub struct GpuEngine {
    gpu: Gpu,
    /// Fixed-step RK4 for the lumped levels, compiled with the engine; the others (Dormand–Prince
    /// 5(4); the `layered` level's RK4 and Dormand–Prince) compiled on first use.
    rk4: wgpu::ComputePipeline,
    dopri5: LazyKernel,
    rk4_layered: LazyKernel,
    dopri5_layered: LazyKernel,
}

/// Compile the kernel for `integrator` (and the `layered` level: [`kernel_source`]) on `device`.
fn compile(
    device: &wgpu::Device,
    integrator: Integrator,
    layered: bool,
) -> Result<wgpu::ComputePipeline, GpuError> {
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("cryoslosh model"),
        source: wgpu::ShaderSource::Wgsl(kernel_source(integrator, layered).into()),
    });
    let entry = match integrator {
        Integrator::Rk4 => "main",
        Integrator::Dopri5 => "main_dopri5",
    };
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(entry),
        layout: None,
        module: &module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    });
    match pollster::block_on(scope.pop()) {
        Some(e) => Err(GpuError::Runtime(format!(
            "the model kernel ({entry}) failed to compile: {e}"
        ))),
        None => Ok(pipeline),
    }
}

/// One instance ready for the device, or already finished on the CPU.
enum Prepared {
    Device(Box<DeviceInstance>),
    Done(Box<InstanceRecord>),
}

/// An instance's resolved inputs, kept for the upload and for completing its summary.
struct DeviceInstance {
    inputs: Vec<f64>,
    params: Params,
    phases: Vec<Phase>,
    s0: State,
    /// `campaign.rtol`, `campaign.atol`.
    tolerance: (f64, f64),
}

impl GpuEngine {
    /// Compile the RK4 kernel on `gpu` (the error-controlled one on first use).
    pub fn new(gpu: Gpu) -> Result<GpuEngine, GpuError> {
        let rk4 = compile(&gpu.device, Integrator::Rk4, false)?;
        Ok(GpuEngine {
            gpu,
            rk4,
            dopri5: LazyKernel::new(),
            rk4_layered: LazyKernel::new(),
            dopri5_layered: LazyKernel::new(),
        })
    }

    /// The adapter this engine runs on.
    pub fn adapter(&self) -> &super::context::AdapterSummary {
        &self.gpu.info
    }

    /// RK4 steps per instance per dispatch: llvmpipe caps an invocation at 65,535 loop
    /// iterations in all (about 120 per lumped step, up to ~170 with the ullage temperature
    /// Newton), hardware only needs dispatches short enough for a display watchdog. A `layered`
    /// column of `layers` layers (0: another level) adds about 350 iterations per step for its
    /// wider state and 50 per layer for its passes (five evaluations of about ten loops over the
    /// layers), so its budget shrinks in proportion (14 steps at 20 layers on llvmpipe).
    fn step_budget(&self, layers: u32) -> u32 {
        let base = if self.gpu.info.hardware { 1024 } else { 128 };
        if layers == 0 {
            return base;
        }
        (base * LUMPED_LOOPS_PER_STEP / (LUMPED_LOOPS_PER_STEP + 350 + 50 * layers)).max(1)
    }

    /// Largest batch of `n_phases`-phase instances one dispatch may hold.
    fn max_batch(&self, n_phases: usize) -> usize {
        let binding = self
            .gpu
            .info
            .max_storage_binding_bytes
            .min(self.gpu.info.max_buffer_bytes);
        let per = [
            size_of::<GpuParams>(),
            size_of::<GpuResult>(),
            n_phases.max(1) * size_of::<GpuPhase>(),
            n_phases.max(1) * size_of::<GpuPhaseResult>(),
        ]
        .into_iter()
        .max()
        .unwrap_or(1) as u64;
        let by_memory = (binding / per) as usize;
        let by_groups = self.gpu.info.max_workgroups_per_dimension as usize * WORKGROUP as usize;
        by_memory.min(by_groups).max(1)
    }

    /// Integrate prepared device instances; results in the same order, and the phase records
    /// (instance × phase, like `phases`). `fixed_steps`: the most steps of any instance under
    /// RK4; `None` integrates with error control, in rounds of dispatches until every instance
    /// is done. `layers`: the `layered` level's layer count (its kernel), 0 for the others.
    #[expect(
        clippy::too_many_arguments,
        reason = "one upload's buffers and its kernel choice"
    )]
    fn dispatch(
        &self,
        layers: u32,
        fluid: &GpuFluid,
        gas: &GpuGas,
        params: &[GpuParams],
        phases: &[GpuPhase],
        table: &[f32],
        fixed_steps: Option<u64>,
    ) -> Result<(Vec<GpuResult>, Vec<GpuPhaseResult>), GpuError> {
        let device = &self.gpu.device;
        let storage = |label: &str, bytes: &[u8]| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: bytes,
                usage: wgpu::BufferUsages::STORAGE,
            })
        };
        let table = if table.is_empty() {
            &[0.0f32][..]
        } else {
            table
        };
        let b_params = storage("params", bytemuck::cast_slice(params));
        let b_phases = storage("phases", bytemuck::cast_slice(phases));
        let b_table = storage("tables", bytemuck::cast_slice(table));
        let b_fluid = storage("fluid", bytemuck::bytes_of(fluid));
        let b_gas = storage("gas", bytemuck::bytes_of(gas));
        // An error-controlled attempt costs about 1,700 loop iterations (seven stages over the
        // state's slots, the error norm, the dense output, the probe), fourteen times an RK4
        // step: an eighth of RK4's budget keeps llvmpipe's 65,535 well away.
        let budget = if fixed_steps.is_some() {
            self.step_budget(layers)
        } else {
            (self.step_budget(layers) / 8).max(1)
        };
        let integrator = if fixed_steps.is_some() {
            Integrator::Rk4
        } else {
            Integrator::Dopri5
        };
        let lazy = match (integrator, layers > 0) {
            (Integrator::Rk4, false) => None,
            (Integrator::Dopri5, false) => Some(&self.dopri5),
            (Integrator::Rk4, true) => Some(&self.rk4_layered),
            (Integrator::Dopri5, true) => Some(&self.dopri5_layered),
        };
        let pipeline = match lazy {
            None => &self.rk4,
            Some(cell) => cell
                .get_or_init(|| compile(device, integrator, layers > 0).map_err(|e| e.to_string()))
                .as_ref()
                .map_err(|e| GpuError::Runtime(e.clone()))?,
        };
        let b_control = storage(
            "control",
            bytemuck::bytes_of(&GpuControl {
                step_budget: budget,
                one: 1.0,
            }),
        );
        let size = (params.len() * size_of::<GpuResult>()) as u64;
        let b_results = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("results"),
            size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let phase_size = (phases.len() * size_of::<GpuPhaseResult>()) as u64;
        let b_phase_results = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("phase results"),
            size: phase_size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        // One readback buffer: the results, then the phase records.
        let b_read = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: size + phase_size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let layout = pipeline.get_bind_group_layout(0);
        let entries: Vec<wgpu::BindGroupEntry> = [
            &b_params,
            &b_phases,
            &b_table,
            &b_fluid,
            &b_gas,
            &b_results,
            &b_control,
            &b_phase_results,
        ]
        .iter()
        .enumerate()
        .map(|(i, b)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: b.as_entire_binding(),
        })
        .collect();
        let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("cryoslosh"),
            layout: &layout,
            entries: &entries,
        });
        // Under RK4 every instance is done after ceil(max_steps / budget) dispatches (the first
        // also initialises); under error control the host dispatches in rounds and reads back
        // until every instance is done. Each dispatch sees the previous one's writes.
        let groups = (params.len() as u32).div_ceil(WORKGROUP);
        let per_round = match fixed_steps {
            Some(n) => n.div_ceil(u64::from(budget)).max(1),
            None => ADAPTIVE_DISPATCHES_PER_ROUND,
        };
        let mut dispatched = 0u64;
        loop {
            let mut enc = device.create_command_encoder(&Default::default());
            for _ in 0..per_round {
                let mut pass = enc.begin_compute_pass(&Default::default());
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, &bind, &[]);
                pass.dispatch_workgroups(groups, 1, 1);
            }
            dispatched += per_round;
            enc.copy_buffer_to_buffer(&b_results, 0, &b_read, 0, size);
            enc.copy_buffer_to_buffer(&b_phase_results, 0, &b_read, size, phase_size);
            let index = self.gpu.queue.submit([enc.finish()]);
            let (tx, rx) = std::sync::mpsc::channel();
            b_read.map_async(wgpu::MapMode::Read, .., move |r| {
                let _ = tx.send(r);
            });
            device
                .poll(wgpu::PollType::Wait {
                    submission_index: Some(index),
                    timeout: None,
                })
                .map_err(|e| GpuError::Runtime(e.to_string()))?;
            rx.recv()
                .map_err(|e| GpuError::Runtime(e.to_string()))?
                .map_err(|e| GpuError::Runtime(e.to_string()))?;
            let view = b_read
                .get_mapped_range(..)
                .map_err(|e| GpuError::Runtime(e.to_string()))?;
            let (head, tail) = view.split_at(size as usize);
            let out = bytemuck::cast_slice::<u8, GpuResult>(head).to_vec();
            let phase_out = bytemuck::cast_slice::<u8, GpuPhaseResult>(tail).to_vec();
            drop(view);
            b_read.unmap();
            let unfinished = out.iter().position(|r| r.done == 0);
            let attempts = dispatched * u64::from(budget);
            match unfinished {
                None => return Ok((out, phase_out)),
                Some(k) if fixed_steps.is_some() || attempts >= MAX_ADAPTIVE_ATTEMPTS => {
                    return Err(GpuError::Runtime(format!(
                        "instance {k} of a batch did not finish in {dispatched} dispatches of \
                         {budget} steps: the driver cut the kernel short, or its steps \
                         collapsed"
                    )));
                }
                Some(_) => {}
            }
        }
    }
}

/// Dispatches per round of error-controlled integration before the host reads back whether
/// every instance is done.
const ADAPTIVE_DISPATCHES_PER_ROUND: u64 = 32;

/// Attempted steps after which an error-controlled batch is abandoned (an instance whose
/// steps collapse is declared diverged by the kernel long before).
const MAX_ADAPTIVE_ATTEMPTS: u64 = 1 << 32;

/// The `layered` level's layer count for `p` (its kernel), 0 at the other levels.
fn kernel_layers(p: &Params) -> u32 {
    if p.fidelity == Fidelity::Layered {
        p.layered
            .layers
            .clamp(1, crate::model::state::NL_MAX as u32)
    } else {
        0
    }
}

/// Loop iterations of one lumped RK4 step in the kernel (see `GpuEngine::step_budget`).
const LUMPED_LOOPS_PER_STEP: u32 = 170;

/// Sample and resolve instance `i`; instances the kernel cannot take finish on the CPU.
fn prepare(plan: &Plan, i: u64) -> Prepared {
    let c = plan.campaign;
    let (inputs, resolved) = plan.resolve(i);
    if let Ok(ci) = &resolved {
        let ci = ci.as_ref().unwrap_or(c);
        if ci.params.fluid == c.params.fluid && ci.phases.len() == c.phases.len() {
            return Prepared::Device(Box::new(DeviceInstance {
                s0: initial_state(ci, &ci.params),
                params: ci.params,
                phases: ci.phases.clone(),
                tolerance: (ci.stepping.rtol, ci.stepping.atol),
                inputs,
            }));
        }
    }
    Prepared::Done(Box::new(plan.record(i, inputs, resolved)))
}

/// The instance summary from the kernel's record and its phase records.
fn summarize(
    p: &Params,
    s0: &State,
    (r, phase_records): (&GpuResult, &[GpuPhaseResult]),
    phase_names: &[String],
) -> Summary {
    let mut s = [0.0; NS];
    for (i, v) in s.iter_mut().enumerate().take(DEVICE_SLOTS) {
        *v = join(r.s_hi[i], r.s_lo[i]);
    }
    let f = f64::from;
    let drew = r.drew != 0;
    let diverged = r.diverged != 0;
    let q = Summary {
        peak_pressure_pa: f(r.peak_pressure_pa),
        peak_pressure_time_s: f(r.peak_pressure_time_s),
        min_pressure_pa: f(r.min_pressure_pa),
        min_pressure_time_s: f(r.min_pressure_time_s),
        min_cavitation_margin_m: drew.then(|| f(r.min_margin_m)),
        min_cavitation_margin_pa: drew.then(|| f(r.min_margin_pa)),
        min_cavitation_margin_time_s: drew.then(|| f(r.min_margin_time_s)),
        max_slosh_angle_rad: f(r.max_slosh_angle_rad),
        peak_slosh_force_n: f(r.peak_slosh_force_n),
        peak_slosh_moment_n_m: f(r.peak_slosh_moment_n_m),
        relief_cycles: u64::from(r.relief_cycles),
        tvs_cycles: u64::from(r.tvs_cycles),
        slosh_out_of_range: r.slosh_out != 0,
        slosh_out_of_range_fraction: if r.final_time_s > 0.0 {
            f(r.slosh_out_time_s) / f(r.final_time_s)
        } else {
            0.0
        },
        pressurant_exhausted: r.exhausted != 0,
        pressurant_exhausted_time_s: (r.exhausted != 0).then(|| f(r.exhausted_time_s)),
        depleted: r.depleted != 0,
        depleted_time_s: (r.depleted != 0).then(|| f(r.depleted_time_s)),
        diverged,
        diverged_reason: diverged.then(|| {
            let what = DIVERGED_REASONS
                .get(r.diverged as usize)
                .copied()
                .unwrap_or("state");
            let phase = phase_names
                .get(r.diverged_phase as usize)
                .map_or("?", String::as_str);
            format!(
                "{what} ({:.6e}) out of range at t = {:.3} s in phase {phase} (GPU)",
                r.diverged_value, r.diverged_time_s
            )
        }),
        ..Summary::default()
    };
    // Lumped levels carry the vapour mass in the state (hi + lo words, more digits than the
    // kernel's f32 derived value); the equilibrium level derives it, on the device both times.
    let homogeneous = p.fidelity == Fidelity::Homogeneous;
    let x = Derived {
        m_vapor_kg: if homogeneous { f(r.m_vapor_kg) } else { s[M_V] },
        t_layer_k: f(r.t_layer_k),
        t_bulk_k: f(r.t_bulk_k),
        p_ullage_pa: f(r.p_ullage_pa),
        ..Derived::default()
    };
    let m_vapor0 = if homogeneous {
        f(r.m_vapor0_kg)
    } else {
        s0[M_V]
    };
    let phases = phase_summaries(p, phase_records, phase_names, m_vapor0, (&s, x.m_vapor_kg));
    let q = Summary { phases, ..q };
    finish_summary(
        q,
        p,
        s0,
        m_vapor0,
        f(r.final_time_s),
        &s,
        &x,
        u64::from(r.steps),
    )
    .with_costs(u64::from(r.rejected), u64::from(r.evaluations))
}

/// The phases an instance entered from their kernel records (`simulate::qoi::Tracker`): a phase
/// ends where the next one starts, the last one entered at the instance's end (`end`: final state
/// and vapour mass, kg); amounts count from the initial vapour mass `m_vapor0`, kg.
fn phase_summaries(
    p: &Params,
    records: &[GpuPhaseResult],
    names: &[String],
    m_vapor0: f64,
    end: (&State, f64),
) -> Vec<PhaseSummary> {
    let start = |ph: &GpuPhaseResult| {
        let mut s = [0.0; NS];
        s[VENT_V] = join(ph.vent_v_hi, ph.vent_v_lo);
        s[VENT_G] = join(ph.vent_g_hi, ph.vent_g_lo);
        s[PRESS_IN] = join(ph.press_in_hi, ph.press_in_lo);
        s[VENT_TVS] = join(ph.vent_tvs_hi, ph.vent_tvs_lo);
        cumulative(p, &s, join(ph.m_vapor_hi, ph.m_vapor_lo), m_vapor0)
    };
    let entered: Vec<&GpuPhaseResult> = records.iter().take_while(|ph| ph.entered != 0).collect();
    let f = f64::from;
    entered
        .iter()
        .enumerate()
        .map(|(i, ph)| {
            let mut q = PhaseSummary::start(&names[i], f(ph.start_pressure_pa), start(ph));
            q.peak_pressure_pa = f(ph.peak_pressure_pa);
            q.min_pressure_pa = f(ph.min_pressure_pa);
            q.max_slosh_angle_rad = f(ph.max_slosh_angle_rad);
            q.min_cavitation_margin_m = (ph.drew != 0).then(|| f(ph.min_margin_m));
            q.close(match entered.get(i + 1) {
                Some(next) => start(next),
                None => cumulative(p, end.0, end.1, m_vapor0),
            });
            q
        })
        .collect()
}

impl Engine for GpuEngine {
    fn name(&self) -> &'static str {
        "gpu"
    }

    fn device(&self) -> String {
        format!(
            "gpu: {} ({})",
            self.gpu.info.name, self.gpu.info.device_type
        )
    }

    fn run_block(&self, plan: &Plan, range: Range<u64>) -> Result<Vec<InstanceRecord>, String> {
        let c = plan.campaign;
        let fixed = c.stepping.integrator == Integrator::Rk4;
        let first = range.start;
        let mut prepared: Vec<Prepared> = range.into_par_iter().map(|i| prepare(plan, i)).collect();
        // Device instances grouped by kernel: the `layered` level's (by layer count) or the
        // others' (0), in instance order within each.
        let mut groups: std::collections::BTreeMap<u32, Vec<usize>> = Default::default();
        for (k, p) in prepared.iter().enumerate() {
            if let Prepared::Device(d) = p {
                groups.entry(kernel_layers(&d.params)).or_default().push(k);
            }
        }
        let (fluid, gas) = fluid_records(c.params.fluid);
        let names: Vec<String> = c.phases.iter().map(|p| p.name.clone()).collect();
        let n_phases = c.phases.len();
        let mut done: Vec<Option<InstanceRecord>> = vec![None; prepared.len()];
        let batches = groups.iter().flat_map(|(&layers, idx)| {
            idx.chunks(self.max_batch(n_phases))
                .map(move |batch| (layers, batch))
        });
        for (layers, batch) in batches {
            let mut tables = Tables::default();
            let mut max_steps = 0u64;
            let mut params = Vec::with_capacity(batch.len());
            let mut phases = Vec::with_capacity(batch.len() * n_phases);
            for &k in batch {
                let Prepared::Device(d) = &prepared[k] else {
                    unreachable!("batch holds device instances only")
                };
                max_steps = max_steps.max(d.phases.iter().map(|x| x.steps().0).sum());
                params.push(GpuParams::new(&d.params, n_phases, &d.s0, d.tolerance));
                phases.extend(d.phases.iter().map(|ph| GpuPhase::new(ph, &mut tables)));
            }
            let (results, phase_results) = self
                .dispatch(
                    layers,
                    &fluid,
                    &gas,
                    &params,
                    &phases,
                    &tables.rows,
                    fixed.then_some(max_steps),
                )
                .map_err(|e| e.to_string())?;
            let summaries: Vec<Summary> = batch
                .par_iter()
                .zip(&results)
                .zip(phase_results.par_chunks(n_phases))
                .map(|((&k, r), ph)| match &prepared[k] {
                    Prepared::Device(d) => summarize(&d.params, &d.s0, (r, ph), &names),
                    Prepared::Done(_) => unreachable!("batch holds device instances only"),
                })
                .collect();
            for (&k, summary) in batch.iter().zip(summaries) {
                let Prepared::Device(d) = &mut prepared[k] else {
                    unreachable!("batch holds device instances only")
                };
                done[k] = Some(InstanceRecord {
                    instance: first + k as u64,
                    inputs: std::mem::take(&mut d.inputs),
                    summary,
                    rejected: false,
                    rejected_by: None,
                });
            }
        }
        Ok(prepared
            .into_iter()
            .zip(done)
            .map(|(p, d)| match p {
                Prepared::Done(r) => *r,
                Prepared::Device(_) => d.expect("every device instance has a result"),
            })
            .collect())
    }
}
