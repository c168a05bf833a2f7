//! The examples in the runtime: every one runs with every built-in policy; the safety
//! examples produce their conflict with `naive` in every seed (a collision, or within 1 m)
//! and `idm` avoids most; runs repeat exactly.

use std::path::Path;
use tad_road::geom::{Footprint, Pose, Vec2};
use tad_runtime::{Episode, Options, Scene, StopReason, run, sample::sample};

fn scene(path: &Path) -> Scene {
    let text = std::fs::read_to_string(path).expect("the example reads");
    let mut db = tad_db::Database::new(tad_check::Options::default());
    let file = db.set_file(path.to_path_buf(), text);
    let scenario = tad_db::resolve(&db, file).clone().expect("an example has a scenario");
    let layout = tad_layout::lay_out(&scenario);
    let program = tad_bytecode::lower(&scenario, &layout, &path.display().to_string());
    Scene::new(&program).expect("a lowered program sets up")
}

fn episode(scene: &Scene, ego: &str, seed: u64) -> Episode {
    let mut policy = tad_policy::parse_policy(ego).unwrap();
    let opts = Options { keep_frames: true, ..Options::default() };
    run(scene, Some(seed), sample(&scene.program.params, Some(seed)), policy.as_mut(), &opts)
}

/// The least bumper-to-bumper distance from the ego to any actor over the episode, m.
fn closest(scene: &Scene, e: &Episode) -> f64 {
    let size = |k: usize| {
        if k == 0 {
            (scene.ego.size.length, scene.ego.size.width)
        } else {
            (scene.actors[k - 1].size.length, scene.actors[k - 1].size.width)
        }
    };
    let fp = |k: usize, (x, y, yaw): (f64, f64, f64)| {
        let (length, width) = size(k);
        Footprint { pose: Pose { position: Vec2::new(x, y), yaw }, length, width }
    };
    e.frames
        .iter()
        .flat_map(|f| (1..f.poses.len()).map(move |k| fp(0, f.poses[0]).distance(&fp(k, f.poses[k]))))
        .fold(f64::INFINITY, f64::min)
}

fn safety() -> Vec<std::path::PathBuf> {
    tad_test_support::examples().into_iter().filter(|p| p.to_string_lossy().contains("safety")).collect()
}

#[test]
fn every_example_runs_with_every_policy() {
    for path in tad_test_support::examples() {
        let scene = scene(&path);
        for ego in ["idm", "naive"] {
            let e = episode(&scene, ego, 0);
            assert!(e.steps >= 1 && e.records.len() == e.steps as usize, "{}", path.display());
            assert!(tad_metrics::score_episode(&e.records, tad_metrics::Mode::Fixed).is_ok(), "{}", path.display());
        }
    }
}

#[test]
fn the_safety_examples_conflict_with_naive_in_every_seed_and_idm_avoids_most() {
    let mut report = Vec::new();
    let mut idm_collisions = 0;
    let mut runs = 0;
    for path in safety() {
        let scene = scene(&path);
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        let mut naive_conflicts = 0;
        for seed in 0..3 {
            let naive = episode(&scene, "naive", seed);
            // a near miss: the ego's box within a metre of another's
            if naive.stop_reason == StopReason::Collision || closest(&scene, &naive) < 1.0 {
                naive_conflicts += 1;
            }
            let idm = episode(&scene, "idm", seed);
            idm_collisions += usize::from(idm.stop_reason == StopReason::Collision);
            runs += 1;
            report.push(format!(
                "{name} seed {seed}: naive {:?} ({:.2} m), idm {:?}",
                naive.stop_reason,
                closest(&scene, &naive),
                idm.stop_reason
            ));
        }
        assert!(
            naive_conflicts == 3,
            "{name}: naive met its conflict in {naive_conflicts} of 3 seeds\n{}",
            report.join("\n")
        );
    }
    assert!(idm_collisions * 3 <= runs, "idm collided in {idm_collisions} of {runs} runs\n{}", report.join("\n"));
}

#[test]
fn the_same_seed_gives_the_same_bytes() {
    for path in safety() {
        let scene = scene(&path);
        let one = episode(&scene, "idm", 7);
        let two = episode(&scene, "idm", 7);
        let bytes = |e: &Episode| serde_json::to_string(&e.records).unwrap();
        assert_eq!(bytes(&one), bytes(&two), "{}", path.display());
        assert_eq!(one.frames, two.frames);
    }
}

#[test]
fn an_episode_stepped_from_outside_is_the_run() {
    // Sim stepped with the idm's answers, view by view, records what `run` records; after
    // the stop nothing moves
    for path in safety().into_iter().take(3) {
        let scene = scene(&path);
        let ran = episode(&scene, "idm", 4);
        let mut idm = tad_policy::parse_policy("idm").unwrap();
        let opts = Options { keep_frames: true, ..Options::default() };
        let mut sim = tad_runtime::Sim::start(&scene, Some(4), sample(&scene.program.params, Some(4)), opts);
        let mut stop = None;
        while let Some(view) = sim.view() {
            let action = idm.act(&view.clone());
            stop = sim.act(action);
        }
        assert_eq!(stop, Some(ran.stop_reason), "{}", path.display());
        assert_eq!(sim.act(tad_policy::Action::default()), stop, "nothing moves after the stop");
        let stepped = sim.finish();
        assert_eq!(stepped.records, ran.records, "{}", path.display());
        assert_eq!((stepped.steps, &stepped.frames), (ran.steps, &ran.frames), "{}", path.display());
    }
}
