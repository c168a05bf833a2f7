//! `lower` on every example and fixture: programs that verify, encode, decode to the same
//! program and disassemble; and what the lowering rules say for particular scenarios.

mod common;

use tad_bytecode::{Instr, Light, Phase, Program, Value, decode, disasm, encode, lower, verify};
use tad_layout::{Arm, Body, Facing, lay_out};

/// What a phase program shows at `t` seconds (it repeats).
fn light_at(phases: &[Phase], t: f64) -> Light {
    let cycle: f64 = phases.iter().map(|p| p.seconds).sum();
    let mut t = t % cycle;
    for p in phases {
        if t < p.seconds {
            return p.light;
        }
        t -= p.seconds;
    }
    phases[phases.len() - 1].light
}

fn signal(p: &Program, arm: Arm) -> Option<&Vec<Phase>> {
    p.code.iter().find_map(|i| match i {
        Instr::Signal { arm: a, phases } if *a == arm => Some(phases),
        _ => None,
    })
}

/// The actor ids of a group's spawns.
fn actors(p: &Program, group: &str) -> Vec<u16> {
    p.code
        .iter()
        .filter_map(|i| match i {
            Instr::Spawn { actor, group: g, .. } if g == group => Some(*actor),
            _ => None,
        })
        .collect()
}

/// An actor's script.
fn script(p: &Program, actor: u16) -> Vec<&Instr> {
    p.code
        .iter()
        .filter(|i| match i {
            Instr::Wait { actor: a, .. }
            | Instr::WaitNear { actor: a, .. }
            | Instr::Drive { actor: a, .. }
            | Instr::Follow { actor: a, .. }
            | Instr::Cross { actor: a, .. }
            | Instr::ChangeLane { actor: a, .. }
            | Instr::Speed { actor: a, .. }
            | Instr::Stop { actor: a }
            | Instr::Signals { actor: a, .. }
            | Instr::Mobil { actor: a, .. } => *a == actor,
            _ => false,
        })
        .collect()
}

#[test]
fn every_example_lowers_encodes_decodes_to_the_same_program_and_disassembles() {
    let examples = common::examples();
    assert!(examples.len() >= 10, "the examples are found");
    for path in examples {
        let name = path.display().to_string();
        let scenario = common::resolved(&path).unwrap();
        let layout = lay_out(&scenario);
        let p = lower(&scenario, &layout, &name);
        verify(&p).unwrap_or_else(|e| panic!("{name}: {e}"));
        let bytes = encode(&p);
        let back = decode(&bytes).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(back, p, "{name}: decode(encode(p)) == p");
        assert_eq!(encode(&back), bytes, "{name}: encoding is deterministic");
        let listing = disasm(&back);
        assert!(listing.contains(&format!("program  {}", p.name)), "{name}: {listing}");
        assert_eq!(
            listing.lines().filter(|l| l.starts_with("  ") && !l.starts_with("  $") && !l.starts_with("  #")).count(),
            p.code.len(),
            "{name}: one line per instruction"
        );
        // every actor the layout has is spawned, in order, with its group's name
        let spawned: Vec<(String, usize)> = p
            .code
            .iter()
            .filter_map(|i| match i {
                Instr::Spawn { group, index, .. } => Some((group.clone(), usize::from(*index))),
                _ => None,
            })
            .collect();
        let laid: Vec<(String, usize)> = layout
            .groups
            .iter()
            .flat_map(|g| {
                let group = &scenario.group(g.group).unwrap().name;
                g.agents.iter().map(move |a| (group.clone(), a.index))
            })
            .collect();
        assert_eq!(spawned, laid, "{name}");
    }
}

#[test]
fn every_fixture_scenario_lowers_to_a_verified_program() {
    let mut lowered = 0;
    for path in common::fixtures() {
        let Some(scenario) = common::resolved(&path) else { continue };
        let layout = lay_out(&scenario);
        let p = lower(&scenario, &layout, "fixture");
        verify(&p).unwrap_or_else(|e| panic!("{}: {e}\n{}", path.display(), disasm(&p)));
        assert_eq!(decode(&encode(&p)).as_ref(), Ok(&p), "{}", path.display());
        lowered += 1;
    }
    assert!(lowered > 20, "only {lowered} fixtures resolved");
}

#[test]
fn mutated_examples_still_lower_to_verified_programs() {
    let mut rng = tad_test_support::mutate::Rng::new(0xB17E);
    let mut lowered = 0;
    for path in common::examples() {
        let text = std::fs::read_to_string(&path).unwrap();
        for round in 0..10 {
            let mutated = match round % 3 {
                0 => tad_test_support::mutate::bytes(&mut rng, &text),
                1 => tad_test_support::mutate::tokens(&mut rng, &text),
                _ => tad_test_support::mutate::words(&mut rng, &text),
            };
            let Some(scenario) = common::resolved_text(&path, mutated.clone()) else { continue };
            let p = lower(&scenario, &lay_out(&scenario), "mutated");
            if let Err(e) = verify(&p) {
                panic!("{} (round {round}): {e}\n{mutated}\n{}", path.display(), disasm(&p));
            }
            lowered += 1;
        }
    }
    assert!(lowered > 100, "only {lowered} mutations resolved");
}

#[test]
fn red_light_running_gives_the_ego_green_the_right_arm_red_and_the_runner_no_respect_for_lights() {
    let p = common::program(&common::example("red_light_running"));
    let ego = signal(&p, Arm::Ego).expect("a light faces the ego");
    let right = signal(&p, Arm::Right).expect("a light faces the right arm");
    assert_eq!(light_at(ego, 0.0), Light::Green);
    assert_eq!(light_at(right, 0.0), Light::Red);
    let runner = actors(&p, "red_light_runner");
    assert_eq!(runner.len(), 1);
    let spawn = p.code.iter().find(|i| matches!(i, Instr::Spawn { actor, .. } if *actor == runner[0])).unwrap();
    assert!(matches!(spawn, Instr::Spawn { arm: Arm::Right, body: Body::Vehicle, .. }), "{spawn:?}");
    let runs = script(&p, runner[0]);
    assert!(runs.contains(&&Instr::Signals { actor: runner[0], obey: false }), "{runs:?}");
    assert!(matches!(runs.last(), Some(Instr::Drive { .. })), "it drives its lane through the junction: {runs:?}");
    // the others keep to the lights
    for other in actors(&p, "oncoming_cars") {
        assert!(!script(&p, other).iter().any(|i| matches!(i, Instr::Signals { .. })));
    }
    let listing = disasm(&p);
    assert!(listing.contains("signals  a0 ignore"), "{listing}");
    assert!(listing.contains("along=52.4+$red_light_runner.spread"), "{listing}");
}

#[test]
fn a_stated_light_holds_twenty_seconds_and_the_crossing_arms_show_its_complement() {
    let path = common::example("red_light_running");
    let text = std::fs::read_to_string(&path).unwrap();
    for (written, ego_light, cross_light) in [
        ("green", Light::Green, Light::Red),
        ("red", Light::Red, Light::Green),
        ("yellow", Light::Yellow, Light::Red),
        ("broken", Light::Off, Light::Off),
    ] {
        let scenario =
            common::resolved_text(&path, text.replace("light: green", &format!("light: {written}"))).unwrap();
        let p = lower(&scenario, &lay_out(&scenario), "x");
        verify(&p).unwrap();
        let arms = [Arm::Ego, Arm::Opposite, Arm::Left, Arm::Right].map(|a| signal(&p, a).unwrap().clone());
        let cycle = |ph: &Vec<Phase>| ph.iter().map(|p| p.seconds).sum::<f64>();
        for k in 0..200 {
            let t = k as f64 * 0.1;
            assert_eq!(light_at(&arms[0], t), ego_light, "{written}: the ego's light at {t} s");
            assert_eq!(light_at(&arms[1], t), ego_light, "{written}: the opposite light at {t} s");
            assert_eq!(light_at(&arms[2], t), cross_light, "{written}: the left light at {t} s");
            assert_eq!(light_at(&arms[3], t), cross_light, "{written}: the right light at {t} s");
        }
        assert!(arms.iter().all(|a| (cycle(a) - cycle(&arms[0])).abs() < 1e-9), "{written}: one cycle");
        let go = |l: Light| matches!(l, Light::Green | Light::Yellow);
        for k in 0..(cycle(&arms[0]) * 10.0) as usize {
            let t = k as f64 * 0.1 + 0.05;
            assert!(!(go(light_at(&arms[0], t)) && go(light_at(&arms[2], t))), "{written}: both axes go at {t} s");
        }
        for phases in &arms {
            for (a, b) in phases.iter().zip(phases.iter().cycle().skip(1)) {
                if a.light == Light::Green {
                    assert_eq!(b.light, Light::Yellow, "{written}: yellow after green");
                    assert!(b.seconds >= 3.0 - 1e-9, "{written}: 3 s of yellow at least");
                }
            }
        }
    }
    let scenario = common::resolved_text(&path, text.replace("light: green", "light: none")).unwrap();
    let p = lower(&scenario, &lay_out(&scenario), "x");
    assert!(signal(&p, Arm::Ego).is_none() && signal(&p, Arm::Right).is_none(), "no light, no signal");
}

#[test]
fn a_road_without_lights_has_no_signal_program() {
    for name in ["lane_changing", "vehicle_passing", "straight_obstacle"] {
        let p = common::program(&common::example(name));
        assert!(!p.code.iter().any(|i| matches!(i, Instr::Signal { .. })), "{name}");
    }
}

#[test]
fn written_ranges_become_parameter_slots() {
    let path = tad_test_support::repo().join("tests/scenic/fixtures/ranges.tad");
    let p = common::program(&path);
    let slot = |name: &str| {
        let i = p.params.iter().position(|s| s.name == name).unwrap_or_else(|| panic!("no slot {name}: {p:#?}"));
        (i as u16, p.params[i].clone())
    };
    let close = |a: f64, b: f64| (a - b).abs() < 1e-9;
    let (ego_speed, s) = slot("ego.speed");
    assert!(close(s.min, 25.0 / 3.6) && close(s.max, 35.0 / 3.6) && close(s.default, 35.0 / 3.6), "{s:?}");
    assert!(
        p.code
            .iter()
            .any(|i| matches!(i, Instr::Ego { speed, .. } if *speed == Value { base: 0.0, slot: Some(ego_speed) }))
    );
    let (delay, s) = slot("lead.delay");
    assert!(close(s.min, 1.0) && close(s.max, 3.0) && close(s.default, 2.0), "{s:?}");
    let (lead_speed, _) = slot("lead.speed");
    let lead = actors(&p, "lead")[0];
    assert_eq!(
        script(&p, lead),
        vec![
            &Instr::Wait { actor: lead, seconds: Value { base: 0.0, slot: Some(delay) } },
            &Instr::Drive {
                actor: lead,
                speed: Value { base: 0.0, slot: Some(lead_speed) },
                turn: tad_layout::Turn::Straight
            },
            // background traffic on a road with lanes beside it
            &Instr::Mobil { actor: lead, on: true },
        ]
    );
    let (trigger, s) = slot("walkers.trigger");
    assert!(close(s.min, 20.0) && close(s.max, 30.0), "{s:?}");
    let (walk, _) = slot("walkers.speed");
    // crossers keep no free room (the layout's slack is 0)
    assert!(!p.params.iter().any(|s| s.name == "walkers.shift"));
    for w in actors(&p, "walkers") {
        assert_eq!(
            script(&p, w),
            vec![
                &Instr::WaitNear { actor: w, distance: Value { base: 0.0, slot: Some(trigger) } },
                &Instr::Cross { actor: w, speed: Value { base: 0.0, slot: Some(walk) } },
            ]
        );
        assert!(p.code.iter().any(|i| matches!(i, Instr::Spawn { actor, along, facing: Facing::Across { .. }, .. } if *actor == w && along.slot.is_none())));
    }
}

#[test]
fn a_scripted_lane_change_drives_its_lane_then_changes_after_a_second_and_a_half() {
    let p = common::program(&common::example("lane_changing"));
    let suv = actors(&p, "merging_suv")[0];
    let s = script(&p, suv);
    assert!(
        matches!(
            s[..],
            [
                Instr::Signals { obey: false, .. },
                Instr::Drive { .. },
                Instr::Wait { .. },
                Instr::ChangeLane { lanes: 1, .. }
            ]
        ),
        "{s:?}"
    );
    assert!(matches!(s[2], Instr::Wait { seconds, .. } if *seconds == Value::lit(1.5)));
}

#[test]
fn standing_actors_have_no_motion_and_baked_paths_are_followed() {
    let p = common::program(&common::example("straight_obstacle"));
    for parked in actors(&p, "parked_sedans") {
        assert!(script(&p, parked).is_empty(), "a parked car does nothing");
    }
    let pedestrian = actors(&p, "darting_pedestrian")[0];
    assert!(matches!(script(&p, pedestrian).last(), Some(Instr::Cross { .. })), "a walker facing across crosses");
    // the ego overtakes: its route is the layout's overtaking path, not its lane
    let p = common::program(&common::example("vehicle_passing"));
    let Some(Instr::Ego { path, start, route_length, .. }) = p.code.iter().find(|i| matches!(i, Instr::Ego { .. }))
    else {
        panic!("no ego")
    };
    let route = &p.paths[usize::from(*path)];
    assert!(route.0.iter().any(|q| q[1] > 0.0), "the overtaking path uses the other lane");
    assert!(start + route_length <= route.length() + 1e-9);
}

/// The ego's route and what its scene times: (route length, stated speed, latest conflict).
fn route_of(name: &str) -> (f64, f64, f64) {
    let path = common::example(name);
    let p = common::program(&path);
    let layout = lay_out(&common::resolved(&path).expect("a scenario"));
    let latest = layout.conflicts.iter().map(|c| c.time).fold(0.0, f64::max);
    let route = p.code.iter().find_map(|i| match i {
        Instr::Ego { route_length, speed, .. } => Some((*route_length, speed.base)),
        _ => None,
    });
    let (route, speed) = route.expect("an ego");
    (route, speed, latest)
}

#[test]
fn a_fast_egos_route_lasts_until_its_scenario_has_happened() {
    // 96.6 km/h on a highway: 100 m would be 3.7 s, before the fast sedan comes alongside
    let (route, speed, latest) = route_of("lane_changing");
    assert!(route >= 6.0 * speed - 1e-6 && route >= (latest + 2.0) * speed - 1e-6, "{route} m at {speed} m/s");
    // 10 km/h through a junction: the junction's rule, the conflict long before its end
    let (route, speed, latest) = route_of("crossing_negotiation");
    assert!(route < 100.0 && route >= (latest + 2.0) * speed, "{route} m at {speed} m/s, conflict at {latest} s");
}
