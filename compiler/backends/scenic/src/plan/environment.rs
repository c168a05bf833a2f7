//! The environment: `carla.WeatherParameters` from the weather's declared sky and road and
//! the time of day's sun (`crate::mapping`), each completed by the vocabulary's first
//! weather or time of day that declares them when only one is given; and the traffic light
//! the CARLA program holds (W0704 under the Newtonian simulator).

use tad_diagnostics::Code;
use tad_ir::Scenario;

use super::Light;
use super::report::{Annotate, Report, named, unsupported};
use super::road::RoadRequest;
use crate::Simulator;
use crate::mapping::{sun_parameters, weather_parameters};

/// The program's environment.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentPlan {
    /// `carla.WeatherParameters`, empty when neither weather nor time is given.
    pub weather: Vec<(&'static str, f64)>,
    /// The names they stand for.
    pub summary: String,
    pub light: Option<Light>,
}

pub fn plan(scenario: &Scenario, road: &RoadRequest, simulator: Simulator, report: &mut Report) -> EnvironmentPlan {
    let entries = &scenario.entries;
    let environment = &scenario.environment;
    let mut parameters = Vec::new();
    let mut said = Vec::new();
    let choices = [
        (
            "weather",
            environment.weather.given().map(|p| p.values().into_iter().map(|n| entries.name(n)).collect::<Vec<_>>()),
            environment.weather.span(),
        ),
        (
            "time",
            environment.time.given().map(|p| p.values().into_iter().map(|n| entries.name(n)).collect::<Vec<_>>()),
            environment.time.span(),
        ),
    ];
    for (field, values, at) in choices {
        let (Some(values), Some(at)) = (values, at) else { continue };
        if values.len() < 2 {
            continue;
        }
        let first = values[0];
        report
            .warn(
                Code::W0707,
                format!(
                    "the program does not sample the choice of {}",
                    if field == "time" { "time of day" } else { "weather" }
                ),
                at,
                format!("`{first}` in every scene"),
                unsupported(format!("environment.{field}"), Some(format!("`{first}`, the first of the choice"))),
            )
            .note("CARLA's weather is one `param weather` of the whole program; a search varies it between programs");
    }
    let weather = environment.weather.clone().map(|p| p.nominal());
    let time = environment.time.clone().map(|p| p.nominal());
    if let (Some(written), Some(at)) = (weather.given(), weather.span()) {
        let name = entries.name(written);
        let p = entries.resolved(written).map(|e| weather_parameters(&e.attrs)).unwrap_or_default();
        if p.is_empty() {
            report
                .warn(
                    Code::W0700,
                    format!("weather `{name}` has no Scenic mapping"),
                    at,
                    "left out of `param weather`",
                    unsupported(named("weather", name), None),
                )
                .note("CARLA's weather has clouds, rain, puddles, wetness, wind and fog, but no snow");
        } else {
            parameters.extend(p);
            said.push(name.to_string());
        }
    }
    if let (Some(written), Some(at)) = (time.given(), time.span()) {
        let name = entries.name(written);
        let p = entries.resolved(written).map(|e| sun_parameters(&e.attrs)).unwrap_or_default();
        if p.is_empty() {
            report.warn(
                Code::W0700,
                format!("time of day `{name}` has no Scenic mapping"),
                at,
                "left out of `param weather`",
                unsupported(named("time_of_day", name), None),
            );
        } else {
            parameters.extend(p);
            said.push(name.to_string());
        }
    }
    if !parameters.is_empty() && !parameters.iter().any(|(k, _)| *k == "sun_altitude_angle") {
        let first =
            entries.times_of_day.iter().map(|(_, e)| (e, sun_parameters(&e.attrs))).find(|(_, p)| !p.is_empty());
        if let Some((e, p)) = first {
            parameters.extend(p);
            said.push(format!("{} (not given)", e.name));
        }
    }
    if !parameters.is_empty() && !parameters.iter().any(|(k, _)| *k == "cloudiness") {
        let first = entries.weather.iter().map(|(_, e)| (e, weather_parameters(&e.attrs))).find(|(_, p)| !p.is_empty());
        if let Some((e, p)) = first {
            parameters.extend(p);
            said.insert(0, format!("{} (not given)", e.name));
        }
    }
    if road.light.is_some() && simulator == Simulator::Newtonian {
        let span = road.light_span.expect("a light state comes from the light field");
        let name = road.light.as_ref().map_or("", |l| l.name.as_str());
        report
            .warn(
                Code::W0704,
                "the Newtonian simulator has no traffic lights",
                span,
                "not simulated",
                unsupported(named("light_state", name), Some("a comment".into())),
            )
            .note("the CARLA program holds this light state with a monitor; build with --simulator carla to keep it");
    }
    EnvironmentPlan { weather: parameters, summary: said.join(", "), light: road.light.clone() }
}
