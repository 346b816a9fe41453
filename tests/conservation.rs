//! MODEL.md §10: mass to 1e-9 and energy to 1e-6 relative on every level and shipped campaign.

mod common;
use common::{load, CAMPAIGNS, LEVELS};
use cryoslosh::simulate::simulate;

#[test]
fn mass_and_energy_close_on_every_campaign_and_level() {
    for name in CAMPAIGNS {
        for level in LEVELS {
            let c = load(name, &[&format!("campaign.fidelity={level}")]);
            let q = simulate(&c, &c.params, None);
            assert!(
                !q.diverged,
                "{name}/{level} diverged: {:?}",
                q.diverged_reason
            );
            eprintln!(
                "{name:16} {level:12} mass {:.2e} energy {:.2e}",
                q.mass_error_rel, q.energy_error_rel
            );
            assert!(
                q.mass_error_rel < 1e-9,
                "{name}/{level}: mass error {:e}",
                q.mass_error_rel
            );
            assert!(
                q.energy_error_rel < 1e-6,
                "{name}/{level}: energy error {:e}",
                q.energy_error_rel
            );
        }
    }
}

#[test]
fn relief_venting_is_conservative_and_counted() {
    // The LCH4 coast vents: vented mass must be positive and the closure must still hold.
    let c = load("lch4_coast", &[]);
    let q = simulate(&c, &c.params, None);
    assert!(
        q.vented_kg > 0.1,
        "expected venting, got {} kg",
        q.vented_kg
    );
    assert!(q.peak_pressure_pa < 1.01 * c.params.relief.unwrap().crack_pa);
    assert!(q.mass_error_rel < 1e-9 && q.energy_error_rel < 1e-6);
}

#[test]
fn slosh_volume_coupling_work_is_accounted() {
    // Paper coupling I (ullage volume follows sin θ): its P dV work enters the energy ledger.
    let c = load("lox_ascent", &["slosh.volume_coupling_m3=0.05"]);
    let q = simulate(&c, &c.params, None);
    assert!(!q.diverged);
    assert!(
        q.mass_error_rel < 1e-9 && q.energy_error_rel < 1e-6,
        "{q:?}"
    );
}
