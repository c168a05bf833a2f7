//! Spelling rules shared by import and export: how a YAML value becomes a TAD name, how
//! a YAML key becomes an actor group name, and the small phrase splits the paper's free
//! text fields need (`two-way straight road with bike lane`, `clear night`).
//!
//! Export uses the same functions to decide whether a name can be written in the paper's
//! spelling (`straight road`) and still read back as the same name; when it cannot, the
//! name is written as it is in TAD (`one_way_street`).

use tad_syntax::schema::Unit;

/// Whether TAD reserves `word` (a keyword or a unit), so that it cannot be a name.
fn reserved(word: &str) -> bool {
    tad_syntax::lexer::KEYWORDS.iter().any(|(k, _)| *k == word) || tad_syntax::lexer::UNITS.contains(&word)
}

/// A YAML value as a TAD name: trimmed, lowercase, spaces and `-` replaced by `_`
/// (`straight road` → `straight_road`, `t-intersection` → `t_intersection`, `SUV` → `suv`).
/// No synonyms are mapped: that is the vocabulary checker's job.
pub fn normalize(text: &str) -> String {
    text.trim()
        .chars()
        .map(|c| if c == '-' || c.is_whitespace() { '_' } else { c.to_ascii_lowercase() })
        .flat_map(char::to_lowercase)
        .collect()
}

/// Whether `name` is a TAD identifier that is not a keyword.
pub fn is_identifier(name: &str) -> bool {
    let mut chars = name.chars();
    let first_ok = chars.next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_');
    first_ok && chars.all(|c| c.is_ascii_alphanumeric() || c == '_') && !reserved(name)
}

/// A YAML key (actor id, scenario name) as a TAD identifier: lowercase, every character
/// that is not an ASCII letter or digit replaced by `_`, `_` in front of a leading digit,
/// `_` after a keyword. Never empty.
pub fn identifier(text: &str) -> String {
    let mut out: String =
        text.trim().chars().map(|c| if c.is_ascii_alphanumeric() { c.to_ascii_lowercase() } else { '_' }).collect();
    if out.is_empty() || out.starts_with(|c: char| c.is_ascii_digit()) {
        out.insert(0, '_');
    }
    if reserved(&out) {
        out.push('_');
    }
    out
}

/// Whether a normalised name means the ego vehicle (`ego_vehicle`, `ego vehicle`, `ego`).
pub fn is_ego(normalized: &str) -> bool {
    matches!(normalized, "ego" | "ego_vehicle" | "the_ego_vehicle" | "the_ego" | "ego_car" | "egovehicle")
}

/// Whether a value is the word `unspecified`.
pub fn is_unspecified(text: &str) -> bool {
    let t = text.trim().trim_end_matches('.').to_ascii_lowercase();
    UNKNOWN_WORDS.contains(&t.as_str())
}

/// What answers write for a value they cannot see (TrafficAlign asks for `unspecified`;
/// models also write these).
const UNKNOWN_WORDS: &[&str] = &[
    "unspecified",
    "unknown",
    "n/a",
    "na",
    "not visible",
    "not_visible",
    "unclear",
    "not clear",
    "not specified",
    "not_specified",
    "not stated",
    "not given",
    "not applicable",
    "undetermined",
    "indeterminate",
    "cannot be determined",
    "can't tell",
    "not sure",
    "uncertain",
    "?",
    "-",
    "--",
    "tbd",
];

/// Words for how many actors a group has that give no number (`several`, `a few`).
pub fn is_count_word(text: &str) -> bool {
    const WORDS: &[&str] = &[
        "several",
        "a few",
        "few",
        "some",
        "many",
        "multiple",
        "a couple",
        "a couple of",
        "couple",
        "numerous",
        "a group",
        "a group of",
        "a number of",
        "lots",
        "a lot",
        "dozens",
        "a handful",
        "handful",
        "various",
    ];
    WORDS.contains(&text.trim().to_ascii_lowercase().as_str())
}

/// Words for a speed that give no number (`slow`), and those that mean standing still.
pub fn speed_word(text: &str) -> Option<SpeedWord> {
    const STILL: &[&str] = &["stopped", "stationary", "parked", "standing still", "not moving", "zero", "standing"];
    const VAGUE: &[&str] = &[
        "slow",
        "slowly",
        "very slow",
        "fast",
        "quickly",
        "quick",
        "moderate",
        "normal",
        "normal speed",
        "high speed",
        "low speed",
        "crawling",
        "walking pace",
        "walking speed",
        "steady",
        "cruising",
        "speeding",
    ];
    let t = text.trim().to_ascii_lowercase();
    if STILL.contains(&t.as_str()) {
        Some(SpeedWord::Still)
    } else if VAGUE.contains(&t.as_str()) {
        Some(SpeedWord::Vague)
    } else {
        None
    }
}

/// What a speed word says.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpeedWord {
    /// 0 km/h.
    Still,
    /// A speed without a number.
    Vague,
}

/// Whether a value is the word `none` (any case).
pub fn is_none_word(text: &str) -> bool {
    let t = text.trim();
    t.eq_ignore_ascii_case("none") || t.eq_ignore_ascii_case("null") || t == "~"
}

/// Words that name a time of day; TrafficComposer folds them into `weather` (`night`).
const TIME_WORDS: &[&str] = &[
    "night",
    "nighttime",
    "night-time",
    "daytime",
    "day",
    "dawn",
    "dusk",
    "evening",
    "morning",
    "afternoon",
    "sunset",
    "sunrise",
    "noon",
    "midnight",
    "twilight",
];

/// `weather` text split into its weather words and its time-of-day words, by whitespace:
/// `clear night` → (`clear`, `night`), `night` → (none, `night`), `partially cloudy` →
/// (`partially cloudy`, none). Words joined by `_` are one word.
pub fn split_weather(text: &str) -> (Option<String>, Option<String>) {
    let words: Vec<&str> = text.split_whitespace().collect();
    let is_time = |w: &&str| TIME_WORDS.contains(&w.to_ascii_lowercase().trim_end_matches([',', '.']));
    if !words.iter().any(is_time) {
        return (Some(text.trim().to_string()), None);
    }
    let weather: Vec<&str> = words.iter().copied().filter(|w| !is_time(w)).collect();
    let time: Vec<&str> = words.iter().copied().filter(is_time).collect();
    let join = |v: Vec<&str>| {
        let s = v.join(" ");
        let s = s.trim_matches([',', '.', ' ']).trim_end_matches(" and").trim_start_matches("and ").to_string();
        (!s.is_empty()).then_some(s)
    };
    (join(weather), join(time))
}

/// What a free-text road type says: `two-way straight road with bike lane` →
/// type `straight road`, direction `two_way`, special lanes `[bike lane]`.
#[derive(Debug, Default, PartialEq)]
pub struct RoadTypeParts {
    /// The road type words, when any are left.
    pub road_type: Option<String>,
    pub direction: Option<&'static str>,
    pub special_lanes: Vec<String>,
}

pub fn split_road_type(text: &str) -> RoadTypeParts {
    let lower = text.trim().to_lowercase();
    let words: Vec<&str> = lower.split_whitespace().collect();
    let mut direction = None;
    let mut kept: Vec<&str> = Vec::new();
    let mut i = 0;
    while i < words.len() {
        let w = words[i].trim_end_matches(',');
        let next = words.get(i + 1).map(|n| n.trim_end_matches(','));
        let found = match (w, next) {
            ("one-way" | "oneway", _) => Some(("one_way", 1)),
            ("two-way" | "twoway", _) => Some(("two_way", 1)),
            ("one", Some("way")) => Some(("one_way", 2)),
            ("two", Some("way")) => Some(("two_way", 2)),
            _ => None,
        };
        match found {
            Some((d, n)) => {
                direction.get_or_insert(d);
                if words[i + n - 1].ends_with(',') {
                    kept.push(",");
                }
                i += n;
            }
            None => {
                kept.push(words[i]);
                i += 1;
            }
        }
    }
    if direction.is_none() && !lower.contains(',') && !lower.contains(" with ") && !lower.contains(" and ") {
        return RoadTypeParts { road_type: Some(text.trim().to_string()), direction: None, special_lanes: Vec::new() };
    }
    let rest = kept.join(" ");
    let mut road_type: Option<String> = None;
    let mut special_lanes = Vec::new();
    for segment in rest.split([',', ';']).flat_map(|s| s.split(" with ")).flat_map(|s| s.split(" and ")) {
        let mut segment = segment.trim();
        for article in ["a ", "an ", "the ", "with "] {
            segment = segment.strip_prefix(article).unwrap_or(segment).trim();
        }
        if segment.is_empty() || segment == "road" && road_type.is_some() {
            continue;
        }
        let lane_like = ["lane", "lanes", "track", "tracks"].iter().any(|l| segment.split(' ').any(|w| w == *l));
        let road_like = ["road", "street", "intersection", "roundabout", "junction", "highway", "avenue"]
            .iter()
            .any(|r| segment.contains(r));
        if lane_like && !road_like {
            special_lanes.push(segment.to_string());
        } else if road_type.is_none() {
            road_type = Some(segment.to_string());
        } else {
            // more road words: keep them with the type rather than drop them
            road_type = road_type.map(|t| format!("{t} {segment}"));
        }
    }
    if road_type.as_deref() == Some("road") {
        road_type = None;
    }
    RoadTypeParts { road_type, direction, special_lanes }
}

/// A number with an optional unit, as LLMs write speeds and times: `30 km/h`, `30km/h`,
/// `"30 mph"`, `5 m/s`, `about 30 km/h`, `~30 kph`. `default` is the unit of a bare
/// number. `None` when the text is not a number with a unit of the same quantity.
pub fn parse_quantity(text: &str, default: Unit) -> Option<(f64, Unit)> {
    let mut t = text.trim().to_lowercase();
    for hedge in ["approximately", "approx.", "approx", "about", "around", "roughly", "~", "≈", "circa", "ca."] {
        if let Some(rest) = t.strip_prefix(hedge) {
            t = rest.trim_start().to_string();
        }
    }
    let split = t.find(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == '+')).unwrap_or(t.len());
    let (number, unit) = t.split_at(split);
    if number.is_empty() || number == "-" || number == "+" {
        return None;
    }
    let value: f64 = number.parse().ok().filter(|v: &f64| v.is_finite())?;
    let unit = unit.trim();
    let unit = match unit {
        "" => default,
        "km/h" | "kmh" | "kph" | "km/hr" | "kmph" | "kilometers per hour" | "kilometres per hour" | "km per hour" => {
            Unit::KilometresPerHour
        }
        "mph" | "mi/h" | "miles per hour" | "mile per hour" => Unit::MilesPerHour,
        "m/s" | "mps" | "meters per second" | "metres per second" => Unit::MetresPerSecond,
        "s" | "sec" | "secs" | "second" | "seconds" => Unit::Seconds,
        "m" | "meter" | "meters" | "metre" | "metres" => Unit::Metres,
        _ => return None,
    };
    (unit.measures() == default.measures()).then_some((value, unit))
}

/// The two ends of a range written in words: `25-30`, `25 - 30`, `25 to 30`,
/// `between 25 and 30` (with any text after them, such as a unit); `None` for anything
/// else, a single number included.
fn range_ends(text: &str) -> Option<(String, String)> {
    let t = text.trim().to_lowercase();
    if let Some(rest) = t.strip_prefix("between ") {
        let (low, high) = rest.split_once(" and ")?;
        return Some((low.trim().to_string(), high.trim().to_string()));
    }
    if let Some((low, high)) = t.split_once(" to ") {
        return Some((low.trim().to_string(), high.trim().to_string()));
    }
    // a `-` after a digit (and spaces): not a sign
    let bytes = t.as_bytes();
    let dash = (1..bytes.len()).find(|&i| {
        bytes[i] == b'-'
            && t[..i].trim_end().as_bytes().last().is_some_and(|b| b.is_ascii_digit() || b.is_ascii_alphabetic())
    })?;
    Some((t[..dash].trim().to_string(), t[dash + 1..].trim().to_string()))
}

/// A range of quantities written as YAML text (`25-30 km/h`, `25 to 30 km/h`,
/// `between 25 and 30 km/h`, `25 km/h - 30 km/h`): both ends in one unit, written after
/// the upper end (and optionally after the lower one too), ordered low to high.
pub fn parse_quantity_range(text: &str, default: Unit) -> Option<(f64, f64, Unit)> {
    let (low, high) = range_ends(text)?;
    let (high, unit) = parse_quantity(&high, default)?;
    let low_has_unit = low.trim_end().ends_with(|c: char| c.is_ascii_alphabetic() || c == '/');
    let (low, low_unit) = parse_quantity(&low, if low_has_unit { default } else { unit })?;
    if low_has_unit && low_unit != unit {
        return None;
    }
    Some((low.min(high), low.max(high), unit))
}

/// A range of whole numbers written as YAML text: `3-5`, `3 to 5`, `between 3 and 5`,
/// ordered low to high.
pub fn parse_integer_range(text: &str) -> Option<(i64, i64)> {
    let (low, high) = range_ends(text)?;
    let (low, high) = (parse_integer(&low)?, parse_integer(&high)?);
    Some((low.min(high), low.max(high)))
}

/// A whole number written as YAML text: `3`, `-1`, `"3"`, `about 10`.
pub fn parse_integer(text: &str) -> Option<i64> {
    let mut t = text.trim().to_lowercase();
    for hedge in ["approximately", "approx.", "approx", "about", "around", "roughly", "~", "circa"] {
        if let Some(rest) = t.strip_prefix(hedge) {
            t = rest.trim_start().to_string();
        }
    }
    let t = t.strip_prefix('+').unwrap_or(&t);
    if t.is_empty() || !t.trim_start_matches('-').bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    t.parse().ok()
}

/// A number word (`two`) as a digit, for help messages.
pub fn number_word(text: &str) -> Option<i64> {
    const WORDS: &[&str] =
        &["zero", "one", "two", "three", "four", "five", "six", "seven", "eight", "nine", "ten", "eleven", "twelve"];
    let t = text.trim().to_ascii_lowercase();
    WORDS.iter().position(|w| *w == t).map(|n| n as i64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names() {
        assert_eq!(normalize(" straight road "), "straight_road");
        assert_eq!(normalize("t-intersection"), "t_intersection");
        assert_eq!(normalize("SUV"), "suv");
        assert_eq!(normalize("ego vehicle"), "ego_vehicle");
        assert!(is_identifier("left_front"));
        assert!(!is_identifier("of"));
        assert!(!is_identifier("mph"));
        assert!(!is_identifier("1st"));
        assert!(!is_identifier("suv/truck"));
        assert_eq!(identifier("Other Actor 1"), "other_actor_1");
        assert_eq!(identifier("1st car"), "_1st_car");
        assert_eq!(identifier("of"), "of_");
        assert_eq!(identifier(""), "_");
    }

    #[test]
    fn weather_and_time() {
        assert_eq!(split_weather("night"), (None, Some("night".into())));
        assert_eq!(split_weather("clear night"), (Some("clear".into()), Some("night".into())));
        assert_eq!(split_weather("partially cloudy"), (Some("partially cloudy".into()), None));
        assert_eq!(split_weather("clear_night"), (Some("clear_night".into()), None));
    }

    #[test]
    fn road_types() {
        let parts = split_road_type("two-way straight road with bike lane");
        assert_eq!(parts.road_type.as_deref(), Some("straight road"));
        assert_eq!(parts.direction, Some("two_way"));
        assert_eq!(parts.special_lanes, vec!["bike lane".to_string()]);
        let parts = split_road_type("one way road");
        assert_eq!((parts.road_type, parts.direction), (None, Some("one_way")));
        assert_eq!(split_road_type("t-intersection").road_type.as_deref(), Some("t-intersection"));
        assert_eq!(split_road_type("one_way_street").road_type.as_deref(), Some("one_way_street"));
        let parts = split_road_type("intersection with tram tracks and bus lane");
        assert_eq!(parts.special_lanes, vec!["tram tracks".to_string(), "bus lane".to_string()]);
    }

    #[test]
    fn quantities() {
        assert_eq!(parse_quantity("30 km/h", Unit::KilometresPerHour), Some((30.0, Unit::KilometresPerHour)));
        assert_eq!(parse_quantity("30mph", Unit::KilometresPerHour), Some((30.0, Unit::MilesPerHour)));
        assert_eq!(parse_quantity("about 3.5 m/s", Unit::KilometresPerHour), Some((3.5, Unit::MetresPerSecond)));
        assert_eq!(parse_quantity("30", Unit::KilometresPerHour), Some((30.0, Unit::KilometresPerHour)));
        assert_eq!(parse_quantity("fast", Unit::KilometresPerHour), None);
        assert_eq!(parse_quantity("30 s", Unit::KilometresPerHour), None);
        assert_eq!(parse_quantity("30-40 km/h", Unit::KilometresPerHour), None);
        assert_eq!(parse_quantity("195 s", Unit::Seconds), Some((195.0, Unit::Seconds)));
        assert_eq!(parse_integer("-2"), Some(-2));
        assert_eq!(parse_integer("about 10"), Some(10));
        assert_eq!(parse_integer("many"), None);
        assert_eq!(parse_integer("2.0"), None);
    }
}
