//! Every kernel the GPU backend can build parses and validates with naga, on any machine: a
//! WGSL error in a level's kernel (the `layered` one is only built for that level) must fail
//! CI without a GPU adapter, not at a user's first run.

use cryoslosh::campaign::Integrator;
use cryoslosh::gpu::engine::kernel_source;

fn validate(integrator: Integrator, layered: bool) -> String {
    let source = kernel_source(integrator, layered);
    let module = naga::front::wgsl::parse_str(&source).unwrap_or_else(|e| {
        panic!(
            "{integrator:?} layered={layered}: {}",
            e.emit_to_string(&source)
        )
    });
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::default(),
    )
    .validate(&module)
    .unwrap_or_else(|e| {
        panic!(
            "{integrator:?} layered={layered}: {}",
            e.emit_to_string(&source)
        )
    });
    source
}

#[test]
fn every_kernel_validates() {
    for integrator in [Integrator::Rk4, Integrator::Dopri5] {
        let lumped = validate(integrator, false);
        let layered = validate(integrator, true);
        // The lumped levels' kernel carries no column: no marker, no column pass.
        assert!(!lumped.contains("LAYERED{") && !lumped.contains("rhs_column"));
        let st = |n: usize| format!("alias St = array<f32, {n}>;");
        assert!(lumped.contains(&st(cryoslosh::model::state::COL)));
        assert!(
            layered.contains("fn rhs_column") && layered.contains(&st(cryoslosh::model::state::NS))
        );
    }
}
