//! The server's settings: the checker options `tadslc check` takes as flags, from the
//! client's `initializationOptions` and `workspace/didChangeConfiguration`.
//!
//! ```json
//! { "tadsl": { "profile": "auto", "region": "yellowstone", "nonScenario": ["weather", "time", "road"] } }
//! ```
//!
//! The object may also come without the `tadsl` wrapper. A missing key keeps its current
//! value; `null` resets it to the default. A value of the wrong kind is reported in words
//! (shown to the user) and ignored, never an error that stops the server.

use serde_json::Value;
use tad_check::{Essential, Options, Profile};

/// Apply `settings` to `options`; the problems found, in words.
pub fn apply(options: &mut Options, settings: &Value) -> Vec<String> {
    let mut problems = Vec::new();
    let settings = settings.get("tadsl").unwrap_or(settings);
    let Some(object) = settings.as_object() else {
        if !settings.is_null() {
            problems.push("settings: expected an object".to_string());
        }
        return problems;
    };
    let defaults = Options::default();
    if let Some(value) = object.get("profile") {
        match value {
            Value::Null => options.profile = defaults.profile,
            Value::String(s) => match profile(s) {
                Some(p) => options.profile = p,
                None => problems.push(format!("tadsl.profile: `{s}` is not one of auto, default, dashcam")),
            },
            _ => problems.push("tadsl.profile: expected a string".to_string()),
        }
    }
    if let Some(value) = object.get("region") {
        match value {
            Value::Null => options.region = None,
            Value::String(s) if s.trim().is_empty() => options.region = None,
            Value::String(s) => options.region = Some(s.trim().to_string()),
            _ => problems.push("tadsl.region: expected a string".to_string()),
        }
    }
    if let Some(value) = object.get("nonScenario").or_else(|| object.get("non_scenario")) {
        match value {
            Value::Null => options.non_scenario = defaults.non_scenario,
            Value::Array(items) => {
                let mut set = Vec::new();
                for item in items {
                    match item.as_str().and_then(Essential::parse) {
                        Some(e) if !set.contains(&e) => set.push(e),
                        Some(_) => {}
                        None => {
                            let names: Vec<&str> = Essential::ALL.iter().map(|e| e.as_str()).collect();
                            problems.push(format!("tadsl.nonScenario: {item} is not one of {}", names.join(", ")));
                        }
                    }
                }
                options.non_scenario = set;
            }
            _ => problems.push("tadsl.nonScenario: expected a list".to_string()),
        }
    }
    problems
}

fn profile(text: &str) -> Option<Profile> {
    match text {
        "auto" => Some(Profile::Auto),
        "default" => Some(Profile::Default),
        "dashcam" => Some(Profile::Dashcam),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn settings_with_or_without_the_wrapper() {
        let mut options = Options::default();
        let problems = apply(
            &mut options,
            &json!({"tadsl": {"profile": "dashcam", "region": "yellowstone", "nonScenario": ["ego"]}}),
        );
        assert!(problems.is_empty(), "{problems:?}");
        assert_eq!(options.profile, Profile::Dashcam);
        assert_eq!(options.region.as_deref(), Some("yellowstone"));
        assert_eq!(options.non_scenario, vec![Essential::Ego]);
        // a missing key keeps its value; null resets
        assert!(apply(&mut options, &json!({"region": null})).is_empty());
        assert_eq!(options.profile, Profile::Dashcam);
        assert_eq!(options.region, None);
    }

    #[test]
    fn wrong_values_are_reported_and_ignored() {
        let mut options = Options::default();
        let problems = apply(&mut options, &json!({"profile": "fast", "region": 3, "nonScenario": ["weather", "sky"]}));
        assert_eq!(problems.len(), 3, "{problems:?}");
        assert_eq!(options.profile, Profile::Auto);
        assert_eq!(options.non_scenario, vec![Essential::Weather]);
        assert_eq!(apply(&mut options, &json!(42)).len(), 1);
        assert!(apply(&mut options, &Value::Null).is_empty());
    }
}
