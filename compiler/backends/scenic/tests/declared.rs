//! Mappings declared beside the vocabulary: a scenario's own declarations carry their
//! Scenic mapping (`simulated_as`, `carla_blueprint`, weather and sun parameters, ...) and
//! the backend uses it as it uses the standard library's; a name without one falls back on
//! its generic attributes (an actor type's kind) with a warning.

mod common;

use std::path::Path;

use tad_diagnostics::{Code, Payload};
use tad_scenic::EmitOptions;

const CAMEL: &str = r#"
actor_type camel {
  kind: animal
  length: 3.0 m
  width: 0.8 m
  height: 2.1 m
  typical_speed: 5 km/h
  max_speed: 65 km/h
  simulated_as: pedestrian
  carla_blueprint: "walker.pedestrian.0002"
}
actor_type dromedary {
  kind: animal
  length: 2.9 m
  width: 0.8 m
  typical_speed: 5 km/h
}
weather sandstorm {
  cloudiness: 30
  wind_intensity: 90
  fog_density: 40
  fog_distance: 5 m
}
time_of_day desert_noon {
  sun_altitude: 85
  sun_azimuth: 180
}
scenario desert_crossing {
  environment {
    weather: sandstorm
    time: desert_noon
  }
  road {
    type: straight_road
    lanes: 1
    direction: two_way
  }
  ego {
    behavior: stopped
    speed: 0 km/h
    lane: 1
  }
  actor caravan: 2 camel {
    behavior: cross
    speed: 4 km/h
    position: front of ego
    lane: 1
  }
  actor stray: 1 dromedary {
    behavior: stand
    speed: 0 km/h
    position: behind of caravan
    lane: 1
  }
}
"#;

#[test]
fn a_declared_actor_type_is_emitted_with_its_own_blueprint() {
    let emitted = common::build_text(Path::new("/nonexistent/desert.tad"), CAMEL, &EmitOptions::default());
    let camels: Vec<&str> = emitted.text.lines().filter(|l| l.starts_with("caravan_")).collect();
    assert_eq!(camels.len(), 2, "{}", emitted.text);
    assert!(camels.iter().all(|l| l.contains("new Pedestrian at")), "{camels:?}");
    assert!(emitted.text.contains("with blueprint 'walker.pedestrian.0002'"), "{}", emitted.text);
    // no approximation warning for the camel: its mapping is its own
    let approximations: Vec<_> = emitted.diagnostics.iter().filter(|d| d.code == Code::W0703).collect();
    assert!(approximations.iter().all(|d| !d.message.contains("camel")), "{approximations:#?}");
    // the dromedary declares none: its kind's (`animal`), approximated and said so
    let dromedary = approximations.iter().find(|d| d.message.contains("`dromedary`")).expect("W0703 for dromedary");
    assert_eq!(
        dromedary.payload,
        Payload::Unsupported {
            backend: "scenic".into(),
            construct: "actor_type dromedary".into(),
            instead: Some("`walker.pedestrian.0001`".into()),
        }
    );
    // the declared weather and sun, as CARLA parameters
    assert!(
        emitted.text.contains(
            "param weather = {'cloudiness': 30.0, 'wind_intensity': 90.0, 'fog_density': 40.0, 'fog_distance': 5.0, \
             'sun_altitude_angle': 85.0, 'sun_azimuth_angle': 180.0}"
        ),
        "{}",
        emitted.text
    );
}

#[test]
fn every_backend_diagnostic_has_a_payload() {
    for example in common::examples() {
        for d in common::build(&example, &EmitOptions::default()).diagnostics {
            assert!(!d.payload.is_none(), "{}: {} {} has no payload", example.display(), d.code, d.message);
        }
    }
    let no_scenario = common::build_text(Path::new("/nonexistent/m.tad"), "weather hail\n", &EmitOptions::default());
    assert!(no_scenario.diagnostics.iter().all(|d| d.code == Code::E0700 && !d.payload.is_none()));
    let unknown = common::build_text(
        Path::new("/nonexistent/camel.tad"),
        CAMEL,
        &EmitOptions { map: Some("Town05".into()), ..EmitOptions::default() },
    );
    let w0705 = unknown.diagnostics.iter().find(|d| d.code == Code::W0705).expect("W0705");
    assert!(matches!(&w0705.payload, Payload::Unknown { namespace, name, candidates, .. }
        if namespace == "map" && name == "Town05" && candidates.iter().any(|c| c == "Town10HD")));
}
