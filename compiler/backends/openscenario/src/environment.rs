//! The scenario's weather and time of day as an OpenSCENARIO `Environment`
//! (`spec/backends/openscenario.md` §3.6), from what the vocabulary declares for them (the
//! CARLA-style 0–100 parameters of a weather, a time of day's sun): clouds in oktas, rain,
//! fog's visual range, wind, the sun, and the road's wetness and friction. A weather that
//! declares nothing, or a choice of several, is a W0710.

use tad_diagnostics::{Code, Diagnostic, Payload};
use tad_ir::Scenario;

use crate::attrs;
use crate::xml::{Xml, num};

/// Heaviest rain (CARLA's precipitation 100), mm/h.
const HEAVY_RAIN: f64 = 10.0;
/// Strongest wind (CARLA's wind intensity 100), m/s.
const GALE: f64 = 20.0;
/// Visual range in clear air, and through the thickest fog from where it begins, m.
const CLEAR_AIR: f64 = 100_000.0;
const FOG_RANGE: f64 = 1_000.0;
/// Illuminance of the sun at the zenith, lux; at night.
const SUNLIGHT: f64 = 100_000.0;
const NIGHT: f64 = 0.001;
/// How much of its friction a fully wet road loses.
const WET_GRIP_LOSS: f64 = 0.4;

const OKTAS: [&str; 9] = [
    "zeroOktas",
    "oneOktas",
    "twoOktas",
    "threeOktas",
    "fourOktas",
    "fiveOktas",
    "sixOktas",
    "sevenOktas",
    "eightOktas",
];

fn share(v: Option<i64>) -> f64 {
    v.map_or(0.0, |v| (v as f64 / 100.0).clamp(0.0, 1.0))
}

fn unsupported(construct: String, instead: &str) -> Payload {
    Payload::Unsupported { backend: "openscenario".into(), construct, instead: Some(instead.into()) }
}

/// `<GlobalAction><EnvironmentAction>` in `Init`, when the scenario states a weather or a time.
pub fn write(x: &mut Xml, scenario: &Scenario, diagnostics: &mut Vec<Diagnostic>) {
    let environment = &scenario.environment;
    let entries = &scenario.entries;
    for (field, span, values) in [
        ("weather", environment.weather.span(), environment.weather.given().map(|p| p.values().len())),
        ("time", environment.time.span(), environment.time.given().map(|p| p.values().len())),
    ] {
        if let (Some(span), Some(n)) = (span, values)
            && n > 1
        {
            let message = format!("the choice of {field} is written as its first");
            let payload = unsupported(format!("environment.{field}"), "the first of the choice");
            let d = Diagnostic::new(Code::W0710, message, span, "one environment per file").with_payload(payload);
            diagnostics.push(
                d.with_note("a parameter value distribution varies numbers, not names; build one file per choice"),
            );
        }
    }
    let weather = environment
        .weather
        .given()
        .map(|p| p.nominal())
        .and_then(|n| Some((entries.name(&n).to_string(), entries.resolved(&n)?.attrs)));
    let sun = environment.time.given().map(|p| p.nominal()).and_then(|n| entries.resolved(&n).map(|e| e.attrs));
    if let (Some((name, w)), Some(span)) = (&weather, environment.weather.span())
        && !w.is_described()
    {
        let message = format!("weather `{name}` declares no parameters");
        let payload = unsupported(format!("weather `{name}`"), "left out of the environment");
        diagnostics.push(Diagnostic::new(Code::W0710, message, span, "not written").with_payload(payload));
    }
    let weather = weather.map(|(_, w)| w).filter(|w| w.is_described());
    if weather.is_none() && sun.is_none() {
        return;
    }
    x.open("GlobalAction", &[]);
    x.open("EnvironmentAction", &[]);
    x.open("Environment", attrs!("name" => "environment"));
    let altitude = sun.as_ref().and_then(|s| s.sun_altitude).map(|a| (a as f64).to_radians());
    let day = altitude.is_none_or(|a| a > 0.0);
    x.empty(
        "TimeOfDay",
        attrs!("animation" => "false", "dateTime" => if day { "2026-06-21T12:00:00" } else { "2026-06-21T23:00:00" }),
    );
    let w = weather.unwrap_or_default();
    let cover = OKTAS[(share(w.cloudiness) * 8.0).round() as usize];
    x.open("Weather", attrs!("fractionalCloudCover" => cover));
    if let Some(s) = &sun {
        let elevation = altitude.unwrap_or(0.0);
        let illuminance = if elevation > 0.0 { SUNLIGHT * elevation.sin() } else { NIGHT };
        let azimuth = s.sun_azimuth.map_or(0.0, |a| (a as f64).rem_euclid(360.0).to_radians());
        x.empty(
            "Sun",
            attrs!("azimuth" => num(azimuth), "elevation" => num(elevation), "illuminance" => num(illuminance)),
        );
    }
    let fog = share(w.fog_density);
    let range =
        if fog > 0.0 { w.fog_distance.map_or(0.0, |d| d.0.max(0.0)) + FOG_RANGE * (1.0 - fog) } else { CLEAR_AIR };
    x.empty("Fog", attrs!("visualRange" => num(range.max(10.0))));
    let rain = share(w.precipitation);
    x.empty(
        "Precipitation",
        attrs!("precipitationType" => if rain > 0.0 { "rain" } else { "dry" }, "precipitationIntensity" => num(rain * HEAVY_RAIN)),
    );
    x.empty("Wind", attrs!("direction" => 0, "speed" => num(share(w.wind_intensity) * GALE)));
    x.close();
    let wetness = share(w.wetness);
    let surface = match (share(w.precipitation_deposits), wetness) {
        (d, _) if d >= 0.5 => "wetWithPuddles",
        (_, v) if v > 0.0 => "moist",
        _ => "dry",
    };
    x.empty("RoadCondition", attrs!("frictionScaleFactor" => num(1.0 - WET_GRIP_LOSS * wetness), "wetness" => surface));
    x.close();
    x.close();
    x.close();
}
