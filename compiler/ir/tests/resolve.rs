//! The IR of the examples and of small scenarios: concrete facts, and totality on mutated
//! inputs. Files are loaded through `tad_db` as the command line does (prelude, `use`).

use std::path::{Path, PathBuf};
use tad_ir::*;

use tad_test_support::mutate::{self, Rng};
use tad_test_support::repo;

fn resolve_text(db: &mut tad_db::Database, path: &Path, text: &str) -> Option<Scenario> {
    let file = db.set_file(path.to_path_buf(), text.to_string());
    let module = &tad_db::analyze(db, file).module;
    let vocabulary = &tad_db::vocabulary(db, file).vocabulary;
    tad_ir::resolve(module, vocabulary)
}

fn example(relative: &str) -> Scenario {
    let path = repo().join("examples").join(relative);
    let text = std::fs::read_to_string(&path).unwrap();
    resolve_text(&mut tad_db::Database::new(Default::default()), &path, &text).expect("a scenario")
}

/// A scenario file of its own, seeing the standard library only.
fn inline(text: &str) -> Scenario {
    let path = std::env::temp_dir().join("tadsl-ir-test").join("inline.tad");
    resolve_text(&mut tad_db::Database::new(Default::default()), &path, text).expect("a scenario")
}

fn examples() -> Vec<PathBuf> {
    let files = tad_test_support::examples();
    assert!(files.len() >= 15, "the examples");
    files
}

/// Every id in the IR indexes its table, and the placement order is a permutation of the
/// groups with every group after the group it refers to (unless in a cycle).
fn assert_consistent(s: &Scenario) {
    let mut order: Vec<usize> = s.placement_order.iter().map(|id| id.index()).collect();
    order.sort();
    assert_eq!(order, (0..s.groups.len()).collect::<Vec<_>>());
    let at = |id: GroupId| s.placement_order.iter().position(|&g| g == id);
    for (id, group) in s.groups() {
        if let Some(position) = group.position.given() {
            if let Named::Known(relation) = position.relation.value {
                assert!(s.entries.get(relation).is_some());
            }
            match position.reference.value {
                Reference::Group(parent) => {
                    assert!(s.group(parent).is_some());
                    let in_cycle = {
                        let mut current = parent;
                        let mut steps = 0;
                        loop {
                            if current == id {
                                break true;
                            }
                            match s.group(current).and_then(|g| g.position.given()).map(|p| &p.reference.value) {
                                Some(Reference::Group(next)) if steps <= s.groups.len() => current = *next,
                                _ => break false,
                            }
                            steps += 1;
                        }
                    };
                    assert!(in_cycle || at(parent) < at(id), "{} before its reference", group.name);
                }
                Reference::RoadElement(element) => assert!(s.entries.get(element).is_some()),
                Reference::Ego | Reference::Unknown(_) => {}
            }
        }
        if let Some(Named::Known(t)) = group.actor_type.given() {
            assert!(s.entries.get(*t).is_some());
        }
    }
}

fn known<K>(named: Option<&Named<K>>) -> bool {
    !matches!(named, Some(Named::Unknown(_)))
}

#[test]
fn every_example_resolves() {
    let mut db = tad_db::Database::new(Default::default());
    for path in examples() {
        let text = std::fs::read_to_string(&path).unwrap();
        let scenario = resolve_text(&mut db, &path, &text).unwrap_or_else(|| panic!("{}", path.display()));
        assert_consistent(&scenario);
        // the examples check without errors: every name they give is declared
        let file = db.set_file(path.clone(), text);
        assert!(!tad_db::check(&db, file).diagnostics.iter().any(|d| d.is_error()), "{}", path.display());
        assert!(known(scenario.ego.behavior.fixed()), "{}", path.display());
        for group in &scenario.groups {
            assert!(known(group.actor_type.given()) && known(group.behavior.fixed()), "{}", path.display());
            if let Some(position) = group.position.given() {
                assert!(!matches!(position.reference.value, Reference::Unknown(_)), "{}", path.display());
                assert!(known(Some(&position.relation.value)), "{}", path.display());
            }
        }
    }
}

#[test]
fn lanes_speeds_and_relations_of_an_example() {
    let s = example("safety/lane_changing.tad");
    assert_eq!(s.name.as_ref().map(|n| n.value.as_str()), Some("lane_changing"));
    assert_eq!(s.road.lanes.get(), Some(4));
    assert_eq!(s.ego.lane.get().map(Lane::index), Some(3));
    let ego_speed = s.ego.speed.fixed().copied().unwrap();
    assert!((ego_speed.km_per_hour() - 96.6).abs() < 1e-9);
    assert_eq!(s.entries.name(s.ego.behavior.fixed().unwrap()), "change_lane_left");
    let behavior = s.entries.resolved(s.ego.behavior.fixed().unwrap()).unwrap();
    assert_eq!(behavior.attrs.motion, Some(Motion::ChangeLaneLeft));
    assert_eq!(behavior.module, "core");

    let suv = &s.groups[s.group_named("merging_suv").unwrap().index()];
    let position = suv.position.given().unwrap();
    let relation = &s.entries.resolved(&position.relation.value).unwrap();
    assert_eq!(relation.name, "left_front");
    assert_eq!(relation.attrs.lateral, Some(Lateral::Left));
    assert_eq!(relation.attrs.longitudinal, Some(Longitudinal::Front));
    assert_eq!(position.reference.value, Reference::Ego);
    // spans point into the file
    let text = std::fs::read_to_string(repo().join("examples/safety/lane_changing.tad")).unwrap();
    let span = position.relation.span;
    assert_eq!(&text[span.start..span.end], "left_front");
    let lane = suv.lane.span().unwrap();
    assert_eq!(&text[lane.start..lane.end], "1");
    let signs = s.road.signs.given().unwrap();
    assert_eq!(signs.len(), 1);
    assert_eq!(s.entries.name(&signs[0].value), "speed_limit_sign");
}

#[test]
fn groups_are_placed_after_their_reference() {
    let s = example("regions/yellowstone_bison_and_tractor.tad");
    let rv = s.group_named("rv_ahead").unwrap();
    let herd = s.group_named("bison_herd").unwrap();
    assert_eq!(s.groups[herd.index()].position.given().unwrap().reference.value, Reference::Group(rv));
    let tractor = &s.groups[s.group_named("oncoming_tractor").unwrap().index()];
    assert!(tractor.lane.get().unwrap().is_opposite());
    assert_eq!(s.groups[herd.index()].count(), Some(5));
    // an animal from `use national_park`, its attributes in SI
    let bison = s.entries.resolved(s.groups[herd.index()].actor_type.given().unwrap()).unwrap();
    assert_eq!((bison.name.as_str(), bison.module.as_str()), ("bison", "national_park"));
    assert_eq!(bison.attrs.length, Some(Metres(3.2)));
    assert!((bison.attrs.max_speed.unwrap().0 - 55.0 / 3.6).abs() < 1e-9);
    assert_eq!(s.entries.get(bison.attrs.kind.unwrap()).map(|k| k.name.as_str()), Some("animal"));
    let light = s.entries.resolved(s.road.light.given().unwrap()).unwrap();
    assert!(!light.attrs.present);
}

#[test]
fn simulator_mappings_are_typed_attributes() {
    let s = example("regions/yellowstone_bison_and_tractor.tad");
    let e = &s.entries;
    let bison = &e[e.actor_types.find("bison").unwrap()].attrs.simulation;
    assert_eq!(bison.simulated_as, Some(SimulatedAs::Pedestrian));
    assert_eq!(bison.carla_blueprint.as_deref(), Some("walker.pedestrian.0001"));
    assert!(bison.carla_note.as_deref().is_some_and(|n| n.contains("no animals")));
    let sedan = &e[e.actor_types.find("sedan").unwrap()].attrs.simulation;
    assert_eq!((sedan.simulated_as, sedan.carla_note.as_deref()), (Some(SimulatedAs::Car), None));
    let vehicle = &e[e.actor_kinds.find("vehicle").unwrap()].attrs.simulation;
    assert_eq!(vehicle.carla_blueprint.as_deref(), Some("vehicle.toyota.prius"));
    let foggy = e[e.weather.find("foggy").unwrap()].attrs;
    assert_eq!((foggy.cloudiness, foggy.fog_density, foggy.fog_distance), (Some(50), Some(60), Some(Metres(10.0))));
    assert!(!e[e.weather.find("snowy").unwrap()].attrs.is_described());
    let night = e[e.times_of_day.find("nighttime").unwrap()].attrs;
    assert_eq!((night.sun_altitude, night.sun_azimuth), (Some(-40), Some(0)));
    assert_eq!(e[e.light_states.find("broken").unwrap()].attrs.signal, Some(Signal::Off));
    assert_eq!(e[e.light_states.find("none").unwrap()].attrs.signal, None);
    let t = e[e.road_types.find("t_intersection").unwrap()].attrs;
    assert_eq!((t.junction, t.arms, t.shape), (true, Some(3), None));
    assert_eq!(e[e.road_types.find("roundabout").unwrap()].attrs.shape, Some(RoadShape::Roundabout));
    assert_eq!(e[e.road_types.find("curved_road").unwrap()].attrs.shape, Some(RoadShape::Curved));
    let dirt = &e[e.road_contexts.find("dirt_road").unwrap()].attrs;
    assert_eq!(dirt.carla_towns, ["Town07"]);
    assert!(dirt.carla_note.is_some());
    assert_eq!(e[e.traffic_signs.find("stop_sign").unwrap()].attrs.opendrive_type, Some(206));
    assert_eq!(e[e.traffic_signs.find("school_zone").unwrap()].attrs.opendrive_type, None);
    assert!(e[e.roadsides.find("sidewalk").unwrap()].attrs.walkway);
    assert!(e[e.road_elements.find("crosswalk").unwrap()].attrs.at_junction);
    assert!(!e[e.road_elements.find("bus_stop").unwrap()].attrs.at_junction);
    let ego = e.reference_points.iter().find_map(|(_, r)| r.attrs.actor_type).unwrap();
    assert_eq!(e[ego].name, "car");
}

const FORWARD_REFERENCES: &str = r#"
scenario aliases_and_references {
  environment {
    weather: sunny
    time: unspecified
  }
  road {
    type: crossroads
    lanes: 2
    direction: two_way
    signs: [stop_sign]
  }
  ego {
    behavior: drive
    speed: 20 mph
  }
  actor follower: unspecified pedestrian {
    behavior: walking
    position: behind of leader
    lane: -2
  }
  actor leader: buffalo {
    position: front_left of zebra_crossing
  }
  actor lost: 2 sedan {
    position: front of nowhere
    speed: 5 m/s
  }
}
"#;

#[test]
fn aliases_units_road_elements_and_forward_references() {
    let s = inline(FORWARD_REFERENCES);
    assert_consistent(&s);
    // aliases resolve to the canonical entry and its typed attributes
    assert_eq!(s.entries.name(s.environment.weather.fixed().unwrap()), "clear");
    let road_type = s.entries.resolved(s.road.road_type.given().unwrap()).unwrap();
    assert_eq!(road_type.name, "intersection");
    assert!(road_type.attrs.junction && road_type.attrs.signalised);
    assert!(matches!(s.environment.time, Field::Unspecified(_)));
    assert_eq!(s.ego.lane, Field::Absent);
    assert_eq!(s.road.context, Field::Absent);
    // mph and m/s in SI
    assert!((s.ego.speed.fixed().copied().unwrap().0 - 20.0 * 1609.344 / 3600.0).abs() < 1e-9);
    let lost = &s.groups[2];
    assert_eq!(lost.speed.fixed().copied(), Some(MetresPerSecond(5.0)));
    assert_eq!(lost.count(), Some(2));
    assert_eq!(lost.position.given().unwrap().reference.value, Reference::Unknown("nowhere".to_string()));

    let follower = &s.groups[0];
    assert!(matches!(follower.count, Field::Unspecified(_)));
    assert_eq!(follower.count(), None);
    assert_eq!(s.entries.name(follower.behavior.fixed().unwrap()), "walk");
    assert_eq!(follower.lane.get().and_then(|l| Lane::new(l.index())), Lane::new(-2));
    // `leader` is written after `follower`, which is positioned relative to it
    assert_eq!(follower.position.given().unwrap().reference.value, Reference::Group(s.group_named("leader").unwrap()));
    assert_eq!(s.placement_order.iter().map(|g| g.index()).collect::<Vec<_>>(), vec![1, 2, 0]);
    // an alias of a road element, and an actor type of a module the file does not use
    let leader = &s.groups[1];
    let position = leader.position.given().unwrap();
    let Reference::RoadElement(element) = position.reference.value else { panic!("a road element") };
    assert_eq!(s.entries[element].name, "crosswalk");
    assert_eq!(s.entries.name(&position.relation.value), "left_front");
    assert_eq!(leader.actor_type.given(), Some(&Named::Unknown("buffalo".to_string())));
    assert_eq!(leader.count(), Some(1));
    assert_eq!(leader.count, Field::Absent);
}

#[test]
fn cycles_and_lanes_counted_from_zero_resolve() {
    let s = inline(
        "scenario cycle {\n  road {\n    lanes: 3\n  }\n  ego {\n    lane: 0\n  }\n\
         actor a: car {\n    position: front of b\n    lane: 2\n  }\n\
         actor b: car {\n    position: front of a\n  }\n\
         actor c: car {\n    position: behind of c\n  }\n}\n",
    );
    assert_consistent(&s);
    assert_eq!(s.placement_order.iter().map(|g| g.index()).collect::<Vec<_>>(), vec![2, 0, 1]);
    assert!(s.lanes_from_zero);
    assert_eq!(s.ego.lane.get().map(Lane::index), Some(1));
    assert_eq!(s.groups[0].lane.get().map(Lane::index), Some(3));
    // lane 0 among 1-based lanes has no meaning
    let s = inline("scenario zero {\n  ego {\n    lane: 0\n  }\n  actor a: car {\n    lane: -1\n  }\n}\n");
    assert!(!s.lanes_from_zero);
    assert_eq!(s.ego.lane, Field::Absent);
}

#[test]
fn a_module_without_a_scenario_has_no_ir() {
    let mut db = tad_db::Database::new(Default::default());
    let path = repo().join("stdlib/national_park.tad");
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(resolve_text(&mut db, &path, &text).is_none());
}

#[test]
fn mutated_examples_resolve_without_panic() {
    const SEED: u64 = 0x7AD5_001A;
    const MUTATIONS: usize = 300;
    let mut db = tad_db::Database::new(Default::default());
    let mut rng = Rng::new(SEED);
    let files = examples();
    for path in files.iter().step_by(3) {
        let text = std::fs::read_to_string(path).unwrap();
        let mutant_path = std::env::temp_dir().join("tadsl-ir-robustness").join(path.file_name().unwrap());
        for iteration in 0..MUTATIONS {
            let mutant = mutate::words(&mut rng, &text);
            let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                if let Some(s) = resolve_text(&mut db, &mutant_path, &mutant) {
                    assert_consistent(&s);
                }
            }));
            assert!(result.is_ok(), "seed {SEED:#x}, {} iteration {iteration}:\n{mutant}", path.display());
        }
    }
}
