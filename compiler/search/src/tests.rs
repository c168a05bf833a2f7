//! Unit tests of the search: ranges move towards collisions, results are seeded and
//! independent of the thread count, the re-fit is mean ± std clipped to the slot, and `fix`
//! writes the chosen parameters (and the layout's room as an `offset`) back.

use super::*;
use tad_policy::parse_policy;

/// A naive ego at 30 km/h behind a car whose speed (0..60 km/h) and place are searched:
/// the ego hits it only when it is slow enough.
fn slow_lead() -> String {
    let text = std::fs::read_to_string(tad_test_support::repo().join("tests/eval/slow_lead.tad")).unwrap();
    text.replace("    lane: 1\n  }\n}", "    lane: 1\n    offset: -5..10 m\n  }\n}")
}

fn compile(src: &str) -> Option<tad_bytecode::Program> {
    let mut db = tad_db::Database::new(tad_check::Options::default());
    let file = db.set_file("search.tad".into(), src.to_string());
    let scenario = tad_db::resolve(&db, file).clone()?;
    let layout = tad_layout::lay_out(&scenario);
    Some(tad_bytecode::lower(&scenario, &layout, "search.tad"))
}

fn scene(src: &str) -> Scene {
    Scene::new(&compile(src).expect("a scenario")).expect("the program sets up")
}

fn naive() -> Box<dyn EgoPolicy> {
    parse_policy("naive").unwrap()
}

#[test]
fn ranges_move_towards_collisions() {
    let scene = scene(&slow_lead());
    assert_eq!(scene.program.params.iter().map(|p| p.name.as_str()).collect::<Vec<_>>(), ["lead.offset", "lead.speed"]);
    let out = search(&scene, &naive, &Config { seed: 3, ..Config::default() }, &|| {});
    assert_eq!(out.trials.len(), 50);
    assert_eq!(out.ranges.len(), 5);
    let rates = out.collision_rates();
    assert!(rates[0] > 0.0 && rates[0] < 1.0, "the first round mixes outcomes: {rates:?}");
    assert!(rates[4] > rates[0], "later rounds collide more: {rates:?}");
    // every collision was with a lead slower than the ego: the speed range closes in on them
    let (low, high) = out.ranges[4][1];
    assert!(high < 60.0 / 3.6 - 3.0, "the speed range shrank towards slow leads: {low}..{high}");
    let slowest_free = out.trials.iter().filter(|t| !t.collision).map(|t| t.params[1]).fold(f64::INFINITY, f64::min);
    let fastest_hit = out.trials.iter().filter(|t| t.collision).map(|t| t.params[1]).fold(0.0, f64::max);
    assert!(fastest_hit < 30.0 / 3.6, "only a lead slower than the ego is hit: {fastest_hit}");
    assert!(slowest_free > 0.0);
    assert_eq!(out.chosen.len(), 2);
    assert!(out.chosen.iter().all(|&i| out.trials[i].collision));
    assert!(out.trials[out.chosen[0]].os() <= out.trials[out.chosen[1]].os());
}

#[test]
fn seeded_and_independent_of_threads() {
    let scene = scene(&slow_lead());
    let config = Config { samples: 20, seed: 9, ..Config::default() };
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| search(&scene, &naive, &config, &|| {}))
    };
    let one = run(1);
    assert_eq!(one, run(2));
    let other = search(&scene, &naive, &Config { seed: 10, ..config.clone() }, &|| {});
    assert_ne!(one.trials[0].params, other.trials[0].params);
}

#[test]
fn refit_is_mean_plus_minus_std_clipped() {
    let slots = vec![
        ParamSlot { name: "a.speed".into(), min: 0.0, max: 10.0, default: 10.0 },
        ParamSlot { name: "a.offset".into(), min: -1.0, max: 1.0, default: 0.0 },
    ];
    let trial = |params: Vec<f64>, collision: bool| Trial {
        index: 0,
        round: 0,
        seed: 0,
        params,
        collision,
        stop: StopReason::MaxSteps,
        score: None,
    };
    let trials = vec![
        trial(vec![2.0, 1.0], true),
        trial(vec![4.0, 1.0], true),
        trial(vec![3.0, 0.1], true),
        trial(vec![9.0, -1.0], false),
    ];
    let ranges = refit(&slots, &[(0.0, 10.0), (-1.0, 1.0)], &trials);
    let std = (2.0f64 / 3.0).sqrt();
    assert!((ranges[0].0 - (3.0 - std)).abs() < 1e-12 && (ranges[0].1 - (3.0 + std)).abs() < 1e-12, "{:?}", ranges[0]);
    // mean 0.7, std 0.42: the upper end is clipped to the slot's
    assert!((ranges[1].0 - (0.7 - 0.18f64.sqrt())).abs() < 1e-12 && ranges[1].1 == 1.0, "{:?}", ranges[1]);
    // one collision is not enough to re-fit
    let ranges = refit(&slots, &[(0.0, 10.0), (-1.0, 1.0)], &trials[2..]);
    assert_eq!(ranges, vec![(0.0, 10.0), (-1.0, 1.0)]);
}

#[test]
fn chosen_scenes_written_with_fixed_parameters_run_as_searched() {
    let searched = scene(&slow_lead());
    let out = search(&searched, &naive, &Config { samples: 20, seed: 5, ..Config::default() }, &|| {});
    for &i in &out.chosen {
        let trial = &out.trials[i];
        let text = fix(&slow_lead(), &searched.program, &trial.params, &compile).unwrap();
        assert!(!text.contains(".."), "no range is left:\n{text}");
        assert!(text.contains("offset: "), "{text}");
        let fixed = scene(&text);
        assert!(fixed.program.params.is_empty(), "{:?}", fixed.program.params);
        let mut ego = naive();
        let episode = tad_runtime::run(&fixed, Some(trial.seed), Vec::new(), ego.as_mut(), &Options::default());
        assert_eq!(episode.stop_reason, trial.stop);
        let os = tad_metrics::score_episode(&episode.records, Mode::Fixed).unwrap().metrics.os;
        assert!((os - trial.os()).abs() < 0.02, "OS {os} against the trial's {}", trial.os());
    }
}

#[test]
fn layout_room_becomes_an_offset() {
    // no offset written: the layout's free room is the slot, written back as `offset`
    let src = slow_lead().replace("    offset: -5..10 m\n", "");
    let searched = scene(&src);
    let names: Vec<&str> = searched.program.params.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["lead.shift", "lead.speed"]);
    let values = [-1.25, 5.0];
    let text = fix(&src, &searched.program, &values, &compile).unwrap();
    assert!(text.contains("    speed: 18 km/h\n") && text.contains("    offset: "), "{text}");
    let fixed = scene(&text);
    let along = |s: &Scene| {
        s.program.code.iter().find_map(|i| match i {
            tad_bytecode::Instr::Spawn { along, .. } => {
                Some(along.base + along.slot.map_or(0.0, |k| values[k as usize]))
            }
            _ => None,
        })
    };
    let (a, b) = (along(&fixed).unwrap(), along(&searched).unwrap());
    assert!((a - b).abs() < 1e-3, "the lead stands where it stood: {a} against {b}");
}

#[test]
fn unknown_slots_are_errors() {
    let slot = |name: &str| ParamSlot { name: name.into(), min: 0.0, max: 1.0, default: 0.0 };
    let program = |names: &[&str]| {
        let mut p = compile(&slow_lead()).unwrap();
        p.params = names.iter().map(|n| slot(n)).collect();
        p
    };
    assert_eq!(
        fix(&slow_lead(), &program(&["nobody.speed"]), &[1.0], &compile),
        Err(FixError::UnknownSlot { slot: "nobody.speed".into() })
    );
    assert!(matches!(
        fix(&slow_lead(), &program(&["lead.colour"]), &[1.0], &compile),
        Err(FixError::UnknownSlot { .. })
    ));
    assert_eq!(fix("scenario {", &program(&[]), &[], &compile), Err(FixError::NoScenario));
    assert_eq!(
        fix(&slow_lead(), &program(&["lead.speed"]), &[], &compile),
        Err(FixError::Mismatch { slots: 1, values: 0 })
    );
    assert_eq!(fix(&slow_lead(), &program(&[]), &[], &|_| None), Err(FixError::Recompile));
}
