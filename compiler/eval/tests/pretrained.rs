//! The shipped driving models drive: on held-out ordinary scenes (`tad_eval::pretrain`'s
//! generators, another seed) each completes its routes about as far as the idm driver and
//! collides at most 1.5 times as often (`cargo test -p tad-eval --test pretrained -- --nocapture`
//! prints the figures).

use tad_eval::pretrain::{HELD_OUT_SEED, judge, scenes};
use tad_policy::EgoSpec;

/// An ego's collision rate and mean route completion over `units` × `seeds`.
fn drive(units: &[tad_eval::Unit], ego: &EgoSpec, seeds: u64) -> (f64, f64) {
    let judged = judge(units, seeds, &|| ego.make());
    (judged.collision_rate, judged.route_complete)
}

fn bar(per_region: usize, seeds: u64) {
    let examples = tad_eval::examples::corpus("examples", "examples/");
    let (units, _) = scenes(&examples, per_region, HELD_OUT_SEED);
    assert!(units.len() >= 10 * per_region, "{} held-out scenes", units.len());
    let (idm_cr, idm_rc) = drive(&units, &EgoSpec::parse("idm").unwrap(), seeds);
    eprintln!("{} scenes × {seeds} seeds: idm CR {idm_cr:.3}, route {idm_rc:.3}", units.len());
    for model in ["ppo", "sac", "td3"] {
        let (cr, rc) = drive(&units, &EgoSpec::parse(model).unwrap(), seeds);
        eprintln!("{model}: CR {cr:.3} ({:.2} × idm), route {rc:.3} ({:.2} × idm)", cr / idm_cr, rc / idm_rc);
        assert!(cr <= 1.5 * idm_cr, "{model} collides in {cr:.3} of the episodes, idm in {idm_cr:.3}");
        assert!(rc >= 0.9 * idm_rc, "{model} completes {rc:.3} of its routes, idm {idm_rc:.3}");
    }
}

/// 30 scenarios per region and generator, 3 seeds each: about 1,000 episodes per driver
/// (on 100 episodes, one driver's collision rate moved by a factor of two with the seed).
#[test]
fn the_shipped_models_drive_as_well_as_idm_on_held_out_scenes() {
    bar(30, 3);
}
